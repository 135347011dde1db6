import numpy as np
import pytest
import pywt

import haarshift


def test_round_trip_is_bit_exact_on_integer_images(camera):
    x = camera.astype(np.float64)
    for layout in ("pyramid", "separable"):
        c = haarshift.transform(x, layout=layout)
        assert c.dtype == np.float64 and c.shape == x.shape
        assert np.array_equal(haarshift.inverse(c, layout=layout), x)
    # float32 is exact where the averages fit its 24 bits: 16 x 16, 4 levels.
    small = camera[:16, :16].astype(np.float32)
    c = haarshift.transform(small)
    assert c.dtype == np.float32
    assert np.array_equal(haarshift.inverse(c), small)


def test_round_trip_of_random_values_and_odd_sizes(rng):
    x = rng.normal(size=(37, 50, 3))
    for padding in ("zero", "edge", "reflect", "wrap"):
        c = haarshift.transform(x, padding=padding, normalization="orthonormal")
        assert c.shape == (64, 64, 3)
        back = haarshift.inverse(c, normalization="orthonormal", shape=x.shape[:2])
        np.testing.assert_allclose(back, x, rtol=0, atol=1e-12)


def test_average_normalisation_on_one_block():
    c = haarshift.transform(np.array([[1.0, 3.0], [5.0, 7.0]]))
    # A = mean, a = (p - q + r - s) / 4, b = (p + q - r - s) / 4, c = (p - q - r + s) / 4
    assert c.tolist() == [[4.0, -1.0], [-2.0, 0.0]]


@pytest.mark.parametrize("shape,levels", [((16, 16), None), ((32, 64), None), ((64, 64), 3)])
def test_orthonormal_pyramid_equals_pywavelets(rng, shape, levels):
    x = rng.normal(size=shape)
    coeffs = pywt.wavedec2(x, "haar", mode="periodization", level=levels)
    want, _ = pywt.coeffs_to_array(coeffs)
    got = haarshift.transform(x, normalization="orthonormal", levels=levels)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
    # And back, against waverec2.
    back = haarshift.inverse(got, normalization="orthonormal", levels=levels)
    np.testing.assert_allclose(back, pywt.waverec2(coeffs, "haar", mode="periodization"), atol=1e-12)


def test_levels_by_name_and_count(rng):
    x = rng.normal(size=(16, 16))
    assert np.array_equal(haarshift.transform(x, levels="full"), haarshift.transform(x))
    one = haarshift.transform(x, levels=1)
    # One step: the top-left quarter holds the 2 x 2 block means.
    np.testing.assert_allclose(one[:8, :8], x.reshape(8, 2, 8, 2).mean(axis=(1, 3)), atol=1e-15)


def test_channels_are_transformed_alone(rng):
    x = rng.normal(size=(8, 16, 3))
    c = haarshift.transform(x)
    for k in range(3):
        assert np.array_equal(c[:, :, k], haarshift.transform(x[:, :, k]))


def test_layouts_and_strides_give_the_same_result(rng):
    x = rng.normal(size=(32, 32))
    want = haarshift.transform(x)
    assert np.array_equal(haarshift.transform(np.asfortranarray(x)), want)
    big = rng.normal(size=(64, 96))
    big[::2, 1::3] = x  # a non-contiguous view holding x
    assert np.array_equal(haarshift.transform(big[::2, 1::3]), want)
    assert np.array_equal(haarshift.transform(x[::-1, ::-1].copy()[::-1, ::-1]), want)
    assert np.array_equal(haarshift.transform(x.tolist()), want)


def test_integer_images_are_transformed_in_float32(camera):
    c = haarshift.transform(camera)
    assert c.dtype == np.float32
    assert np.array_equal(c, haarshift.transform(camera.astype(np.float32)))
    sixteen = camera.astype(np.uint16) * 257
    assert np.array_equal(haarshift.transform(sixteen), haarshift.transform(sixteen.astype(np.float32)))


def test_agrees_with_the_command_line(cli, tmp_path, rng):
    x = rng.normal(size=(20, 24, 3))
    src = tmp_path / "x.npy"
    np.save(src, x)
    out = tmp_path / "c.npy"
    cli("transform", src, "-o", out, "--norm", "orthonormal", "--layout", "separable", "--pad", "reflect")
    from_cli = np.moveaxis(np.load(out), 0, -1)  # the CLI writes (C, H, W)
    ours = haarshift.transform(x, normalization="orthonormal", layout="separable", padding="reflect")
    assert np.array_equal(ours, from_cli)

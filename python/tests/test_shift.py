import numpy as np
import pytest

import haarshift


def periodic_linear(x, dx, dy):
    """Periodic bilinear interpolation: out[r, c] = x(r - dy, c - dx)."""
    def along(a, s, axis):
        k = int(np.floor(s))
        t = s - k
        return (1 - t) * np.roll(a, k, axis=axis) + t * np.roll(a, k + 1, axis=axis)
    return along(along(x, dx, 1), dy, 0)


def test_whole_shifts_are_rolls(camera):
    x = camera.astype(np.float64)
    for dx, dy in [(3, -5), (-17, 0), (0, 200)]:
        assert np.array_equal(haarshift.shift(x, dx, dy), np.roll(x, (dy, dx), axis=(0, 1)))
        assert np.array_equal(haarshift.shift(camera, dx, dy), np.roll(camera, (dy, dx), axis=(0, 1)))
        for method in ("nearest", "linear", "keys", "bspline3", "lanczos3", "fft"):
            got = haarshift.shift(x[:64, :64], dx, dy, method=method)
            np.testing.assert_allclose(got, np.roll(x[:64, :64], (dy, dx), axis=(0, 1)), atol=1e-9)


@pytest.mark.parametrize("precision", [1, 2, 3])
def test_compact_haar_is_linear_interpolation_at_the_rounded_shift(rng, precision):
    x = rng.normal(size=(32, 64))
    dx, dy = 0.3, -1.7
    step = 2.0 ** -precision
    rounded = [np.floor(s / step + 0.5) * step for s in (dx, dy)]  # ties upwards
    got = haarshift.shift(x, dx, dy, precision=precision)
    np.testing.assert_allclose(got, periodic_linear(x, *rounded), atol=1e-12)


def test_retained_haar_is_finer_and_averages_to_the_compact_result(rng):
    x = rng.normal(size=(16, 16))
    fine = haarshift.shift(x, 0.25, 0.5, precision=2, retain=True)
    assert fine.shape == (64, 64)
    compact = haarshift.shift(x, 0.25, 0.5, precision=2)
    np.testing.assert_allclose(fine.reshape(16, 4, 16, 4).mean(axis=(1, 3)), compact, atol=1e-12)


def test_integer_images_round_to_codes(camera):
    got = haarshift.shift(camera, 0.5, 0.0, precision=1)
    assert got.dtype == np.uint8
    want = haarshift.shift(camera.astype(np.float32), 0.5, 0.0, precision=1)
    assert np.array_equal(got, np.clip(np.floor(want.astype(np.float64) + 0.5), 0, 255).astype(np.uint8))


def test_agrees_with_the_command_line(cli, tmp_path, rng):
    x = rng.normal(size=(24, 40)).astype(np.float32)
    src, out = tmp_path / "x.npy", tmp_path / "s.npy"
    np.save(src, x)
    cli("shift", src, "-o", out, "--dx", "2.25", "--dy", "-1.5", "--method", "bspline3", "--boundary", "reflect")
    ours = haarshift.shift(x, 2.25, -1.5, method="bspline3", boundary="reflect")
    assert np.array_equal(ours, np.load(out))

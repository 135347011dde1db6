import numpy as np
import pytest

import haarshift


def solid_angles(h):
    """Solid angle of each row's pixels of an h x 2h lat-long map."""
    edges = np.linspace(0.0, np.pi, h + 1)
    return (np.cos(edges[:-1]) - np.cos(edges[1:])) * (np.pi / h)


def test_a_whole_column_yaw_is_a_roll(rng):
    m = rng.normal(size=(16, 32, 3))
    for method in ("haar", "haar-cubic", "bilinear", "bicubic", "reference"):
        # yaw 45 degrees is 4 of 32 columns: output column j shows input column j + 4.
        got = haarshift.sphere.rotate(m, yaw=45.0, method=method)
        assert np.array_equal(got, np.roll(m, -4, axis=1)), method


def test_rotation_matches_the_reference(rng):
    y = np.linspace(-1, 1, 32)[:, None] * np.ones((1, 64))
    smooth = 2.0 + y
    truth = haarshift.sphere.rotate(smooth, pitch=30.0, method="reference")
    haar = haarshift.sphere.rotate(smooth, pitch=30.0)
    assert haar.shape == (32, 64) and haar.dtype == np.float64
    weights = solid_angles(32)[:, None]
    rms = np.sqrt((weights * (haar - truth) ** 2).sum() / weights.sum() / 64)
    assert rms < 0.02
    single = haarshift.sphere.rotate(smooth.astype(np.float32), pitch=30.0)
    assert single.dtype == np.float32
    np.testing.assert_allclose(single, haar, atol=1e-5)


def test_integral_equals_the_pixel_sum(rng):
    a, b = rng.uniform(0.5, 2.0, size=(2, 16, 32))
    c = rng.uniform(0.5, 2.0, size=(16, 32, 3))
    w = solid_angles(16)[:, None]
    want = (a * b * w).sum()
    got = haarshift.sphere.integrate([a, b])
    assert isinstance(got, float)
    assert abs(got - want) < 1e-12 * want
    per_channel = haarshift.sphere.integrate([a, b, c], method="triple")
    want3 = (a[..., None] * b[..., None] * c * w[..., None]).sum(axis=(0, 1))
    np.testing.assert_allclose(per_channel, want3, rtol=1e-12)
    pixel = haarshift.sphere.integrate([a, b], method="pixel")
    assert abs(pixel - want) < 1e-12 * want


def test_pruned_integral_is_the_integral_of_pruned_maps(rng):
    a, b = rng.uniform(0.5, 2.0, size=(2, 16, 32))
    full = haarshift.sphere.integrate([a, b])
    kept = haarshift.sphere.integrate([a, b], keep=[20, 510])
    assert kept != full
    assert abs(kept - full) < 0.05 * abs(full)
    with pytest.raises(ValueError, match="keep"):
        haarshift.sphere.integrate([a, b], keep=10_000)


def test_product_equals_the_pixelwise_product(rng):
    a = rng.uniform(0.5, 2.0, size=(8, 16))
    b = rng.uniform(0.5, 2.0, size=(8, 16, 3))
    got = haarshift.sphere.product([a, b])
    assert got.shape == (8, 16, 3)
    np.testing.assert_allclose(got, a[..., None] * b, rtol=0, atol=1e-12)
    cube = haarshift.sphere.product([a, b], param="cube")
    assert cube.shape == (6, 4, 4, 3)


def test_integer_maps_round_back_to_codes(rng):
    m = rng.integers(0, 256, size=(8, 16, 3), dtype=np.uint8)
    rolled = haarshift.sphere.rotate(m, yaw=45.0)  # two of 16 columns: exact
    assert rolled.dtype == np.uint8 and np.array_equal(rolled, np.roll(m, -2, axis=1))
    tilted = haarshift.sphere.rotate(m, pitch=20.0, method="bilinear")
    want = haarshift.sphere.rotate(m.astype(np.float32), pitch=20.0, method="bilinear")
    assert tilted.dtype == np.uint8
    assert np.array_equal(tilted, np.clip(np.floor(want.astype(np.float64) + 0.5), 0, 255).astype(np.uint8))

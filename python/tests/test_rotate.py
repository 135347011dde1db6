import threading
import time

import numpy as np
import pytest

import haarshift

METHODS = ["nearest", "linear", "keys", "bspline3", "bspline5", "lanczos3", "lanczos4", "fft", "haar"]


@pytest.mark.parametrize("method", METHODS)
def test_quarter_turns_are_rot90(rng, method):
    x = rng.normal(size=(31, 31, 2)).astype(np.float32)
    for k, angle in enumerate([0, 90, 180, 270]):
        assert np.array_equal(haarshift.rotate(x, angle, method=method), np.rot90(x, k))
    tall = rng.normal(size=(20, 12))
    assert np.array_equal(haarshift.rotate(tall, -90, method=method, canvas="expand"), np.rot90(tall, -1))


@pytest.mark.parametrize("method", METHODS)
def test_a_constant_stays_constant(method):
    x = np.full((48, 64), 7.0)
    got = haarshift.rotate(x, 30, method=method, fill=7.0)
    np.testing.assert_allclose(got, 7.0, rtol=0, atol=1e-9)
    edge = haarshift.rotate(x, -12.5, method=method, boundary="edge", canvas="expand")
    np.testing.assert_allclose(edge, 7.0, rtol=0, atol=1e-9)


def test_expand_holds_the_whole_image():
    got = haarshift.rotate(np.ones((20, 30), dtype=np.float32), 30, method="keys", canvas="expand")
    assert got.shape == (32, 36) and got.dtype == np.float32
    assert abs(got[16, 18] - 1.0) < 1e-6 and got[0, 0] == 0.0


def test_layouts_and_strides_give_the_same_result(rng):
    x = rng.normal(size=(40, 56, 3)).astype(np.float32)
    want = haarshift.rotate(x, 17.0, method="keys")
    assert np.array_equal(haarshift.rotate(np.asfortranarray(x), 17.0, method="keys"), want)
    padded = np.zeros((80, 112, 6), dtype=np.float32)
    padded[::2, ::2, ::2] = x
    assert np.array_equal(haarshift.rotate(padded[::2, ::2, ::2], 17.0, method="keys"), want)


def test_rotator_equals_rotate_and_writes_into_out(rng):
    x = rng.normal(size=(64, 48)).astype(np.float32)
    rotator = haarshift.Rotator(method="keys", canvas="expand", fill=1.5)
    want = haarshift.rotate(x, 23.0, method="keys", canvas="expand", fill=1.5)
    for _ in range(3):
        assert np.array_equal(rotator(x, 23.0), want)
    out = np.empty_like(want)
    assert rotator.rotate(x, 23.0, out=out) is out
    assert np.array_equal(out, want)
    with pytest.raises(ValueError, match="out: shape"):
        rotator.rotate(x, 23.0, out=np.empty((3, 3), dtype=np.float32))
    with pytest.raises(ValueError, match="out: expected a f32 array"):
        rotator.rotate(x, 23.0, out=np.empty_like(want, dtype=np.float64))
    frozen = np.empty_like(want)
    frozen.flags.writeable = False
    with pytest.raises(ValueError, match="out"):
        rotator.rotate(x, 23.0, out=frozen)
    assert "keys" in repr(rotator) and "expand" in repr(rotator)


def test_integer_images_round_to_codes(camera):
    got = haarshift.rotate(camera, 30)
    assert got.dtype == np.uint8
    want = haarshift.rotate(camera.astype(np.float32), 30)
    assert np.array_equal(got, np.clip(np.floor(want.astype(np.float64) + 0.5), 0, 255).astype(np.uint8))


def test_agrees_with_the_command_line(cli, tmp_path, rng):
    x = rng.normal(size=(33, 47, 3)).astype(np.float32)
    src, out = tmp_path / "x.npy", tmp_path / "r.npy"
    np.save(src, x)
    cli("rotate", src, "-o", out, "--angle", "30", "--method", "lanczos3", "--canvas", "expand")
    ours = haarshift.rotate(x, 30, method="lanczos3", canvas="expand")
    assert np.array_equal(ours, np.load(out))


def test_long_calls_release_the_gil(rng):
    """Another Python thread runs while a rotation computes."""
    x = rng.normal(size=(2048, 2048)).astype(np.float32)
    ticks = []
    stop = threading.Event()

    def tick():
        while not stop.is_set():
            ticks.append(time.perf_counter())

    thread = threading.Thread(target=tick)
    thread.start()
    try:
        start = time.perf_counter()
        haarshift.rotate(x, 30, method="bspline5", supersample=1)
        end = time.perf_counter()
    finally:
        stop.set()
        thread.join()
    inside = [t for t in ticks if start < t < end]
    # With the GIL held the other thread could not take a single step inside the call.
    assert len(inside) > 100, (len(inside), end - start)

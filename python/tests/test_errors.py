import numpy as np
import pytest

import haarshift

GOOD = np.zeros((8, 8))


@pytest.mark.parametrize("call", [
    lambda x: haarshift.transform(x),
    lambda x: haarshift.rotate(x, 10),
    lambda x: haarshift.shift(x, 0.5),
])
def test_bad_arrays(call):
    nan = GOOD.copy()
    nan[3, 4] = np.nan
    with pytest.raises(ValueError, match=r"non-finite value NaN at index \[3, 4\]"):
        call(nan)
    inf = GOOD.astype(np.float32)
    inf[0, 1] = np.inf
    with pytest.raises(ValueError, match="non-finite value inf"):
        call(inf)
    with pytest.raises(ValueError, match=r"image: expected a 2D \(H, W\) or 3D \(H, W, C\) array, got 1"):
        call(np.zeros(8))
    with pytest.raises(ValueError, match="got 4 dimensions"):
        call(np.zeros((2, 2, 2, 2)))
    with pytest.raises(ValueError, match=r"image: array of shape \[0, 5\] is empty"):
        call(np.zeros((0, 5)))
    with pytest.raises(ValueError, match="dtype int64 is not supported"):
        call(np.zeros((4, 4), dtype=np.int64))
    with pytest.raises(ValueError, match="dtype bool is not supported"):
        call(np.zeros((4, 4), dtype=bool))


def test_bad_arguments():
    with pytest.raises(ValueError, match=r'invalid shift method: unknown value "cubic" \(expected one of: nearest,'):
        haarshift.rotate(GOOD, 10, method="cubic")
    with pytest.raises(ValueError, match="invalid precision"):
        haarshift.shift(GOOD, 0.5, precision=99)
    with pytest.raises(ValueError, match="precision applies to method haar only, not keys"):
        haarshift.rotate(GOOD, 10, method="keys", precision=2)
    with pytest.raises(ValueError, match="keys_a applies to method keys only"):
        haarshift.shift(GOOD, 1.0, keys_a=-0.75)
    with pytest.raises(ValueError, match="supersample: 9 is above the largest, 8"):
        haarshift.rotate(GOOD, 10, supersample=9)
    with pytest.raises(ValueError, match="invalid angle"):
        haarshift.rotate(GOOD, float("nan"))
    with pytest.raises(ValueError, match="invalid fill"):
        haarshift.rotate(GOOD, 10, fill=float("inf"))
    with pytest.raises(ValueError, match="give fill or boundary, not both"):
        haarshift.rotate(GOOD, 10, fill=1.0, boundary="edge")
    with pytest.raises(ValueError, match="the Haar shift is periodic"):
        haarshift.shift(GOOD, 0.5, boundary="reflect")
    with pytest.raises(ValueError, match="invalid shift"):
        haarshift.shift(GOOD, float("inf"))
    with pytest.raises(ValueError, match="invalid levels: 4 levels requested but this size allows at most 3"):
        haarshift.transform(GOOD, levels=4)
    with pytest.raises(ValueError, match='levels: "three" is neither'):
        haarshift.transform(GOOD, levels="three")
    with pytest.raises(ValueError, match="invalid layout"):
        haarshift.transform(GOOD, layout="mallat")
    with pytest.raises(ValueError, match="invalid shape"):
        haarshift.inverse(np.zeros((6, 8)))
    with pytest.raises(ValueError, match="lat-long map"):
        haarshift.sphere.rotate(np.zeros((8, 8)), yaw=10)
    with pytest.raises(ValueError, match="give two or more"):
        haarshift.sphere.integrate([np.ones((4, 8))])
    with pytest.raises(MemoryError, match="memory budget"):
        haarshift.rotate(np.zeros((4096, 4096), dtype=np.float32), 10, supersample=8)


def test_file_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="missing.png"):
        haarshift.read_image(tmp_path / "missing.png")
    corrupt = tmp_path / "corrupt.png"
    corrupt.write_bytes(b"\x89PNG\r\n\x1a\n" + b"\0" * 40)
    with pytest.raises(OSError, match="corrupt.png"):
        haarshift.read_image(corrupt)
    out = tmp_path / "out.png"
    haarshift.write_image(out, np.zeros((4, 4), dtype=np.uint8))
    with pytest.raises(FileExistsError, match="already exists"):
        haarshift.write_image(out, np.zeros((4, 4), dtype=np.uint8))
    haarshift.write_image(out, np.full((4, 4), 9, dtype=np.uint8), force=True)
    assert haarshift.read_image(out)[0, 0] == 9
    with pytest.raises(OSError, match="cannot tell the output format"):
        haarshift.write_image(tmp_path / "out.xyz", GOOD)


def test_io_round_trips(tmp_path, rng, camera):
    assert camera.dtype == np.uint8 and camera.shape == (512, 512)
    for dtype, name in [(np.uint8, "a.png"), (np.uint16, "b.tif"), (np.float32, "c.exr"), (np.float64, "d.npy")]:
        x = (rng.uniform(0, 200, size=(6, 10, 3))).astype(dtype)
        haarshift.write_image(tmp_path / name, x)
        back = haarshift.read_image(tmp_path / name)
        assert back.dtype == dtype and np.array_equal(back, x), name

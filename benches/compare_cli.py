#!/usr/bin/env python3
"""Times the `haarshift` command line, whole process, against Python + OpenCV and ImageMagick.

Every job runs `--repeats` times (default 5) under `/usr/bin/time`; the table gives the
medians of wall time, CPU time (user + sys) and peak resident memory, and the ratios to the
peer measured in the same run. Inputs are made in a temporary directory:

* `gray.npy`: a 2048x2048 float32 image (the pattern of benches/rotate.rs);
* `rgb.png`: 2048x2048 RGB 8-bit, testdata/astronaut.png enlarged 4x (bicubic), so that PNG
  sizes are those of a photograph.

Jobs: `rotate` by 30 degrees with keys (.npy in and out) against a Python script doing the
same with OpenCV `warpAffine` INTER_CUBIC (interpreter start, imports and .npy I/O included);
`rotate --canvas expand` of the PNG against ImageMagick 6 `convert -rotate 30` (black
background) writing PNG with adaptive filtering at zlib level 4 (`-quality 45`), whose files
are the size of haarshift's (fdeflate's fast mode, adaptive filter), and at zlib level 1
(`-quality 15`), ImageMagick's fastest; angle 0 (read and write only); `shift`, `transform`
and `inverse` on the `.npy` image. Output file sizes are listed under the table.

    pip install numpy opencv-python-headless      # and: apt-get install imagemagick
    cargo build --release -p haarshift-cli
    python3 benches/compare_cli.py --out benches/cli_results.md

Python and ImageMagick are only for this comparison; haarshift never needs them.
"""

import argparse
import math
import os
import pathlib
import shutil
import statistics
import subprocess
import sys
import tempfile
import textwrap

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
ANGLE = 30

OPENCV_SCRIPT = textwrap.dedent(
    """
    import sys
    import cv2
    import numpy as np
    img = np.load(sys.argv[1])
    h, w = img.shape
    m = cv2.getRotationMatrix2D(((w - 1) / 2, (h - 1) / 2), float(sys.argv[3]), 1.0)
    out = cv2.warpAffine(img, m, (w, h), flags=cv2.INTER_CUBIC, borderValue=0)
    np.save(sys.argv[2], out)
    """
)


def make_inputs(directory, n):
    import cv2

    y, x = np.mgrid[0:n, 0:n].astype(np.float32) / np.float32(n)
    gray = (np.sin(40 * x * y) + 0.5 * np.cos(13 * x - 7 * y)).astype(np.float32)
    np.save(directory / "gray.npy", gray)
    photo = cv2.imread(str(ROOT / "testdata" / "astronaut.png"), cv2.IMREAD_COLOR)
    big = cv2.resize(photo, (n, n), interpolation=cv2.INTER_CUBIC)
    cv2.imwrite(str(directory / "rgb.png"), big)
    (directory / "rotate_cv2.py").write_text(OPENCV_SCRIPT)


def measure(command, repeats, cwd, clean):
    """Medians over `repeats` runs: wall s, CPU s, peak RSS MiB."""
    walls, cpus, rss = [], [], []
    for _ in range(repeats):
        for path in clean:
            path.unlink(missing_ok=True)
        result = subprocess.run(
            ["/usr/bin/time", "-f", "%e %U %S %M", *command],
            cwd=cwd,
            capture_output=True,
            text=True,
        )
        if result.returncode != 0:
            sys.exit(f"{' '.join(command)} failed:\n{result.stderr}")
        e, u, s, m = result.stderr.strip().splitlines()[-1].split()
        walls.append(float(e))
        cpus.append(float(u) + float(s))
        rss.append(int(m) / 1024)
    return statistics.median(walls), statistics.median(cpus), statistics.median(rss)


def row(job, ours, peer=None, peer_name=""):
    wall, cpu, rss = ours
    cells = [job, f"{wall:.3f}", f"{cpu:.3f}", f"{rss:.0f}"]
    if peer is None:
        cells += ["", "", "", "", "", ""]
    else:
        pw, pc, pr = peer
        cells += [
            peer_name,
            f"{pw:.3f}",
            f"{pc:.3f}",
            f"{pr:.0f}",
            f"{wall / pw:.2f} / {cpu / pc:.2f}",
            f"{rss / pr:.2f}",
        ]
    return "| " + " | ".join(cells) + " |"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--binary", default=str(ROOT / "target" / "release" / "haarshift"))
    ap.add_argument("--size", type=int, default=2048)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--out", help="also write the table to this Markdown file")
    args = ap.parse_args()
    for tool in ["convert", "/usr/bin/time"]:
        if shutil.which(tool) is None:
            sys.exit(f"{tool} is needed (apt-get install imagemagick time)")

    hs = os.path.abspath(args.binary)
    n, r = args.size, args.repeats
    with tempfile.TemporaryDirectory() as tmp:
        d = pathlib.Path(tmp)
        make_inputs(d, n)
        out_npy, out_png = d / "out.npy", d / "out.png"
        coeffs = d / "coeffs.npy"
        coeffs_json = d / "coeffs.npy.json"
        rotate = [hs, "rotate", "--method", "keys", "--angle", str(ANGLE)]
        jobs = {}
        jobs["opencv"] = measure(
            [sys.executable, "rotate_cv2.py", "gray.npy", "cv.npy", str(ANGLE)], r, d, []
        )
        jobs["npy"] = measure([*rotate, "gray.npy", "-o", "out.npy"], r, d, [out_npy])
        jobs["zero"] = measure(
            [hs, "rotate", "--method", "keys", "--angle", "0", "gray.npy", "-o", "out.npy"],
            r,
            d,
            [out_npy],
        )
        for level in [1, 4]:
            jobs[f"magick {level}"] = measure(
                ["convert", "rgb.png", "-background", "black", "-rotate", str(ANGLE),
                 "-quality", f"{level}5", f"im{level}.png"],
                r,
                d,
                [d / f"im{level}.png"],
            )
        im_sizes = {level: (d / f"im{level}.png").stat().st_size for level in [1, 4]}
        jobs["png"] = measure(
            [*rotate, "--canvas", "expand", "rgb.png", "-o", "out.png"], r, d, [out_png]
        )
        png_size = out_png.stat().st_size
        jobs["shift"] = measure(
            [hs, "shift", "--dx", "0.3", "--dy", "0.7", "gray.npy", "-o", "out.npy"],
            r,
            d,
            [out_npy],
        )
        jobs["shift keys"] = measure(
            [hs, "shift", "--method", "keys", "--dx", "0.3", "--dy", "0.7", "gray.npy", "-o",
             "out.npy"],
            r,
            d,
            [out_npy],
        )
        jobs["transform"] = measure(
            [hs, "transform", "gray.npy", "-o", "coeffs.npy"], r, d, [coeffs, coeffs_json]
        )
        jobs["inverse"] = measure([hs, "inverse", "coeffs.npy", "-o", "out.npy"], r, d, [out_npy])

    uptime = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    mib = n * n * 4 / 2**20
    side = math.floor(n * (math.cos(math.radians(ANGLE)) + math.sin(math.radians(ANGLE))) + 0.5)
    expand_mib = side * side * 4 / 2**20
    lines = [
        f"CLI against peers, whole process, {n}x{n}, median of {r} runs "
        f"(`python3 benches/compare_cli.py`; load: `{uptime.split('load average:')[-1].strip()}`).",
        "Time ratio: wall / CPU (user + sys); below 1 haarshift is faster.",
        "",
        "| job | haarshift wall s | CPU s | peak MiB | peer | peer wall s | CPU s | peak MiB "
        "| time ratio | memory ratio |",
        "|---|---:|---:|---:|---|---:|---:|---:|---:|---:|",
        row(f"rotate {ANGLE} deg, keys, f32 .npy in and out", jobs["npy"], jobs["opencv"],
            "Python + OpenCV warpAffine cubic"),
        row(f"rotate {ANGLE} deg, keys, --canvas expand, RGB 8-bit PNG", jobs["png"],
            jobs["magick 4"], "ImageMagick convert -rotate, PNG zlib 4 (same size)"),
        row("(same job)", jobs["png"], jobs["magick 1"],
            "ImageMagick convert -rotate, PNG zlib 1 (fastest)"),
        row("rotate 0 deg (read and write only), f32 .npy", jobs["zero"]),
        row("shift (0.3, 0.7), haar h=3, f32 .npy", jobs["shift"]),
        row("shift (0.3, 0.7), keys, f32 .npy", jobs["shift keys"]),
        row("transform, f32 .npy -> f64 coefficients", jobs["transform"]),
        row("inverse, coefficients -> f32 .npy", jobs["inverse"]),
        "",
        f"PNG output sizes: haarshift {png_size / 2**20:.2f} MiB; ImageMagick at zlib 4 "
        f"{im_sizes[4] / 2**20:.2f} MiB (ratio {png_size / im_sizes[4]:.2f}), at zlib 1 "
        f"{im_sizes[1] / 2**20:.2f} MiB (ratio {png_size / im_sizes[1]:.2f}).",
        f"Peak memory over input + output image in f32: .npy rotation "
        f"{jobs['npy'][2] / (2 * mib):.2f}x ({2 * mib:.0f} MiB), PNG rotation "
        f"{jobs['png'][2] / (3 * (mib + expand_mib)):.2f}x ({3 * (mib + expand_mib):.0f} MiB).",
    ]
    table = "\n".join(lines) + "\n"
    print(table)
    if args.out:
        pathlib.Path(args.out).write_text(table)


if __name__ == "__main__":
    main()

"""Shared fixtures: test images made here or read from the repository's testdata/, and the
command-line binary that `cargo test --workspace --release` builds."""
import os
import pathlib
import shutil
import subprocess

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def camera():
    """The 512 x 512 8-bit camera photograph (testdata/camera.png) as uint8."""
    import haarshift

    return haarshift.read_image(ROOT / "testdata" / "camera.png")


@pytest.fixture
def rng():
    return np.random.default_rng(20081122)


@pytest.fixture(scope="session")
def cli():
    """Runs the haarshift binary, target/release/haarshift (which `cargo build --release -p
    haarshift-cli` builds, as does `cargo test --workspace --release`) or else the one on the
    PATH; skips, saying how to build it, when there is neither (CI builds it first)."""
    binary = ROOT / "target" / "release" / "haarshift"
    if not binary.exists():
        found = shutil.which("haarshift")
        if found is None:
            pytest.skip(
                "target/release/haarshift not built: run cargo build --release -p haarshift-cli"
            )
        binary = pathlib.Path(found)

    def run(*args, check=True):
        """The finished process; with check (the default) it must have succeeded."""
        result = subprocess.run([str(binary), *map(str, args)], capture_output=True, text=True)
        assert result.returncode == 0 or not check, result.stderr
        return result

    return run


def needs(component, missing):
    """Skips the calling test, saying why, when `missing` (what is missing and how to install
    it) is not None, unless HAARSHIFT_REQUIRE lists `component`: then the test fails, so that
    CI can never pass by skipping. Skips are listed in pytest's summary (-rs, pyproject.toml)."""
    if missing is None:
        return
    required = [c.strip() for c in os.environ.get("HAARSHIFT_REQUIRE", "").split(",")]
    if component in required:
        pytest.fail(f"{component} is required (HAARSHIFT_REQUIRE) but missing: {missing}")
    pytest.skip(f"{missing}")

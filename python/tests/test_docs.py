"""Every public function and class documents itself with examples that run."""
import doctest
import inspect

import pytest

import haarshift

PUBLIC = [getattr(haarshift, name) for name in haarshift.__all__ if name not in ("__version__", "relight", "sphere")]
PUBLIC += [haarshift.sphere.rotate, haarshift.sphere.integrate, haarshift.sphere.product]
PUBLIC += [haarshift.relight.scene, haarshift.relight.precompute, haarshift.relight.merge]


@pytest.mark.parametrize("obj", PUBLIC, ids=lambda o: o.__name__)
def test_docstring_examples_run(obj):
    assert obj.__doc__ and len(obj.__doc__) > 80, f"{obj.__name__} has no useful docstring"
    tests = doctest.DocTestFinder().find(obj, obj.__name__, globs={})
    examples = sum(len(t.examples) for t in tests)
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE)
    for test in tests:
        runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.failed == 0
    assert examples > 0, f"{obj.__name__} has no example"


def test_signatures_show_in_help():
    assert "method='bspline3'" in str(inspect.signature(haarshift.rotate))
    assert "precision=None" in str(inspect.signature(haarshift.shift))
    assert "out=None" in str(inspect.signature(haarshift.Rotator.rotate))

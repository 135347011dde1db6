#!/usr/bin/env python3
"""List the test helper functions defined more than once under one name within a crate.

Exits 1 when there is any (listing each name with the places it is defined), 0 when there is
none. Run from anywhere: `python3 scripts/test_helper_names.py`.

The rule, checked by name only:

* A crate is a directory tree: the core is `src/`, `tests/`, `examples/` and `benches/`; every
  other crate is its own directory (`relight/`, `experiments/`, `cli/` with its `src/` and
  `tests/`, `viewer/`, `python/`, `testkit/`, `tools/measure/`, `fuzz/`).
* Test code is a whole file when it is named `tests.rs`, `*_tests.rs` or `test_support.rs`,
  lies under a `tests/` directory, or is named by a `#[cfg(test)]` module declaration
  (`#[cfg(test)] #[path = "..."] mod tests;`); elsewhere it is the body of a
  `#[cfg(test)] mod NAME { ... }`.
* A test helper is a `fn` item in test code that is not a test: a function carrying `#[test]`
  (also inside `proptest!`) is named for what it tests, and two modules may well test the same
  thing under one name. Methods (a `fn` inside an `impl` or `trait` block) are namespaced by
  their type and are not counted. A `fn` nested inside another function's body is counted:
  a helper written again inside a test body is as much a near-copy as one beside it.
* Two definitions of one name in one crate are a duplicate, whether they do the same thing
  (merge them into the crate's `test_support.rs`, or use the library's function) or different
  things (rename one so the name says what it does).
"""

import os
import re
import sys
from collections import defaultdict

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# Crate name -> directories (relative to the root) that make it up.
CRATES = {
    "haarshift": ["src", "tests", "examples", "benches"],
    "haarshift-relight": ["relight"],
    "haarshift-experiments": ["experiments"],
    "haarshift-cli": ["cli"],
    "haarshift-viewer": ["viewer"],
    "haarshift-python": ["python"],
    "haarshift-testkit": ["testkit"],
    "haarshift-measure": ["tools/measure"],
    "fuzz": ["fuzz"],
}
SKIP_DIRS = {"target", ".git", "corpus", "artifacts", "node_modules"}

TEST_ATTR = re.compile(r"#\s*\[\s*(?:\w+\s*::\s*)*test\s*\]")
CFG_TEST = re.compile(r"#\s*\[\s*cfg\s*\(\s*test\s*\)\s*\]")
FN_NAME = re.compile(r"\bfn\s+([A-Za-z_][A-Za-z0-9_]*)")


def strip(text):
    """The source with comments, strings and char literals blanked (newlines kept)."""
    out = []
    i, n = 0, len(text)

    def blank(s):
        return "".join("\n" if c == "\n" else " " for c in s)

    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(blank(text[i:j]))
            i = j
        elif text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append(blank(text[i:j]))
            i = j
        else:
            m = re.match(r'b?r(#*)"', text[i:i + 260])
            if m and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
                end = '"' + m.group(1)
                j = text.find(end, i + m.end())
                j = n if j < 0 else j + len(end)
                out.append(blank(text[i:j]))
                i = j
            elif c == '"':
                j = i + 1
                while j < n and text[j] != '"':
                    j += 2 if text[j] == "\\" else 1
                out.append(blank(text[i:j + 1]))
                i = j + 1
            elif c == "'":
                m = re.match(r"'(\\.[^']*|[^\\'])'", text[i:i + 12])
                if m:
                    out.append(blank(m.group(0)))
                    i += m.end()
                else:  # a lifetime
                    out.append(c)
                    i += 1
            else:
                out.append(c)
                i += 1
    return "".join(out)


def is_test_file(rel):
    parts = rel.split("/")
    name = parts[-1]
    return (
        name in ("tests.rs", "test_support.rs")
        or name.endswith("_tests.rs")
        or "tests" in parts[:-1]
    )


def test_module_files(path, code):
    """Files named by `#[cfg(test)] [#[path = ".."]] mod NAME;` declarations in `path`."""
    found = []
    raw = open(path, encoding="utf-8").read()
    for m in re.finditer(
        r"#\s*\[\s*cfg\s*\(\s*test\s*\)\s*\]\s*(#\s*\[\s*path\s*=\s*\"([^\"]+)\"\s*\]\s*)?"
        r"(?:pub(?:\([^)]*\))?\s+)?mod\s+(\w+)\s*;",
        raw,
    ):
        here = os.path.dirname(path)
        if m.group(2):
            found.append(os.path.normpath(os.path.join(here, m.group(2))))
        else:
            stem = os.path.splitext(os.path.basename(path))[0]
            base = here if stem in ("mod", "lib", "main") else os.path.join(here, stem)
            for cand in (m.group(3) + ".rs", os.path.join(m.group(3), "mod.rs")):
                found.append(os.path.normpath(os.path.join(base, cand)))
    return found


def helpers(code, whole_file_is_test):
    """(name, line, nested) of each helper `fn` in the test code of one stripped file."""
    stack = []  # (kind, is_test) of each open brace
    boundary = 0  # where the current item header starts
    result = []
    i = 0
    for m in re.finditer(r"[{};]|\bfn\s+[A-Za-z_]\w*", code):
        tok = m.group(0)
        in_test = whole_file_is_test or any(t for _, t in stack)
        header = code[boundary:m.start()]
        if tok.startswith("fn"):
            kinds = [k for k, _ in stack]
            in_impl = bool(kinds) and kinds[-1] in ("impl", "trait")
            if in_test and not in_impl and not TEST_ATTR.search(header):
                name = FN_NAME.match(tok).group(1)
                line = code.count("\n", 0, m.start()) + 1
                result.append((name, line, "fn" in kinds))
            continue
        if tok == "{":
            h = re.sub(r"#\s*!?\s*\[[^\]]*\]", " ", header)  # drop attributes
            if FN_NAME.search(h):
                kind = "fn"
            elif re.search(r"(^|\s)(unsafe\s+)?impl\b", h):
                kind = "impl"
            elif re.search(r"(^|\s)(pub(\([^)]*\))?\s+)?(unsafe\s+)?trait\b", h):
                kind = "trait"
            elif re.search(r"(^|\s)(pub(\([^)]*\))?\s+)?mod\s+\w+\s*$", h):
                kind = "mod"
            else:
                kind = "block"
            stack.append((kind, kind == "mod" and bool(CFG_TEST.search(header))))
        elif tok == "}":
            if stack:
                stack.pop()
        boundary = m.end()
    return result


def main():
    os.chdir(ROOT)
    duplicates = 0
    for crate, dirs in CRATES.items():
        files = []
        for d in dirs:
            for dirpath, dirnames, filenames in os.walk(d):
                dirnames[:] = sorted(x for x in dirnames if x not in SKIP_DIRS)
                files += [os.path.join(dirpath, f) for f in sorted(filenames) if f.endswith(".rs")]
        codes = {f: strip(open(f, encoding="utf-8").read()) for f in files}
        declared = set()
        for f in files:
            declared.update(test_module_files(f, codes[f]))
        defs = defaultdict(list)
        for f in files:
            whole = is_test_file(f) or os.path.normpath(f) in declared
            for name, line, nested in helpers(codes[f], whole):
                defs[name].append(f"{f}:{line}" + (" (nested)" if nested else ""))
        for name, places in sorted(defs.items()):
            if len(places) > 1:
                duplicates += 1
                print(f"{crate}: fn {name} defined {len(places)} times")
                for p in places:
                    print(f"    {p}")
    if duplicates:
        print(f"{duplicates} test helper name(s) defined more than once within a crate")
        return 1
    print("no test helper is defined twice under one name in a crate")
    return 0


if __name__ == "__main__":
    sys.exit(main())

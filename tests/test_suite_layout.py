"""The suite collects in any order: pytest (rootdir-based ``prepend`` import mode) puts each
test folder that is not a package on ``sys.path``, so a module name that two such folders
share is whichever was collected first (``tests/fuzz/strategies.py`` shadowed
``tests/strategies.py`` until tests/fuzz became a package)."""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

TESTS = Path(__file__).resolve().parent


def test_no_two_bare_importable_test_modules_share_a_name():
    names = defaultdict(list)
    for path in TESTS.rglob("*.py"):
        folder = path.parent
        inside_package = any((p / "__init__.py").is_file()
                             for p in [folder, *folder.parents] if p != TESTS.parent
                             and p.is_relative_to(TESTS))
        if not inside_package:
            names[path.stem].append(str(path.relative_to(TESTS)))
    assert {k: v for k, v in names.items() if len(v) > 1} == {}

"""``tools/lint_model.py`` (run by ``make lint``) on planted files: it must fail on string
dispatch against a registry name outside the model and on a function over 80 lines, and pass
what the rules allow (issue 26)."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "tools" / "lint_model.py"
NAMES = "rotvec,rate-three,conventional,single-chain,table3,coning"


def _lint(path: Path, *, names: str | None = NAMES) -> subprocess.CompletedProcess[str]:
    args = [sys.executable, str(SCRIPT), str(path)]
    if names is not None:
        args[2:2] = ["--names", names]
    return subprocess.run(args, capture_output=True, text=True, timeout=300)


def _plant(tmp_path: Path, where: str, text: str) -> Path:
    """A file at ``tmp/strapdown/<where>`` (so its package path is ``where``)."""
    path = tmp_path / "strapdown" / where
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text))
    return path


DISPATCH = """
    def pick(spec):
        if spec.family.name == "rate-three":
            return 3
        return 1
"""


def test_dispatch_on_a_family_name_outside_the_model_fails(tmp_path):
    res = _lint(_plant(tmp_path, "apps/planted.py", DISPATCH))
    assert res.returncode == 1
    assert "planted.py:3: name-dispatch" in res.stdout and "'rate-three'" in res.stdout


@pytest.mark.parametrize("text", [
    "ok = structure in ('conventional', 'realtime')\n",
    "ok = 'table3' != spec.coefficients\n",
    "match motion:\n    case 'coning':\n        pass\n",
])
def test_every_comparison_form_fails(tmp_path, text):
    assert _lint(_plant(tmp_path, "analysis/planted.py", text)).returncode == 1


def test_the_model_may_dispatch_on_its_names(tmp_path):
    assert _lint(_plant(tmp_path, "algorithms/spec.py", DISPATCH)).returncode == 0


def test_other_strings_and_a_marked_vocabulary_pass(tmp_path):
    text = """
        a = mode == "auto"
        b = target == "coning"  # lint-model: a designer's target, not the motion
    """
    assert _lint(_plant(tmp_path, "cli/planted.py", text)).returncode == 0
    unexplained = 'b = target == "coning"  # lint-model:\n'
    assert _lint(_plant(tmp_path, "cli/bare.py", unexplained)).returncode == 1


def _function(lines: int, decorator: str = "", docstring: int = 0) -> str:
    """A function of ``lines`` lines from ``def`` to its end, plus a docstring."""
    doc = ['    """' + "x" * 10] + ["    prose"] * max(docstring - 2, 0) + ['    """'] \
        if docstring else []
    body = [f"    x{k} = {k}" for k in range(lines - 2)] + ["    return 0"]
    return "\n".join([decorator, "def f():", *doc, *body, ""]).lstrip("\n")


def test_a_function_of_81_lines_fails_and_80_pass(tmp_path):
    res = _lint(_plant(tmp_path, "apps/long.py", _function(81)))
    assert res.returncode == 1 and "f is 81 lines" in res.stdout
    assert _lint(_plant(tmp_path, "apps/short.py", _function(80))).returncode == 0


def test_a_docstring_does_not_count_and_a_kernel_is_exempt(tmp_path):
    assert _lint(_plant(tmp_path, "apps/doc.py", _function(80, docstring=30))).returncode == 0
    kernel = _function(120, decorator="@njit(cache=True)")
    assert _lint(_plant(tmp_path, "algorithms/_k.py", kernel)).returncode == 0
    assert _lint(_plant(tmp_path, "algorithms/_j.py", _function(120))).returncode == 1


def test_the_package_itself_passes():
    res = _lint(ROOT / "src" / "strapdown", names=None)  # the registries' own names
    assert res.returncode == 0, res.stdout + res.stderr


def test_the_designer_is_linted_like_everything_else(tmp_path):
    """The allow-list is empty: a planted dispatch in design/ fails as anywhere outside the
    model (the designer asks its target, layout and form objects)."""
    sys.path.insert(0, str(SCRIPT.parent))
    try:
        import lint_model
    finally:
        sys.path.remove(str(SCRIPT.parent))
    assert lint_model.ALLOWED == {}
    assert _lint(_plant(tmp_path, "design/designer.py", DISPATCH)).returncode == 1

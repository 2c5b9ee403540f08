"""Lint that keeps the algorithm model one model (``make lint``; issue 26).

Two rules, checked on the syntax tree of every ``.py`` file given (directories are walked):

``name-dispatch``
    A comparison (``==``, ``!=``, ``in``, ``not in``, ``is``, a ``match`` case) against a
    registry name — a family (``"rate-three"``), an update structure (``"single-chain"``),
    a coefficient set (``"table3"``) or a motion (``"coning"``) — outside the model's own
    modules (:data:`MODEL_MODULES`). Such a comparison restates a fact the registered object
    answers itself, and silently leaves out whatever is registered next: ask the object
    (``spec.structure.chains``, ``spec.family.stepped``, ``motion.law`` …) instead.
``long-function``
    A function (or method) longer than :data:`MAX_LINES` lines, from its ``def`` to its last
    line, its docstring not counted. Numba kernels (decorated ``@njit``, ``@jit`` …) are
    exempt: a kernel is one loop the compiler fuses, and splitting it costs speed. A C
    template is text: it belongs in a template file, not a function body.

Files the model did not own yet were exempt through :data:`ALLOWED` (path → rules), each
entry with the reason; the list is empty now and is not to grow again. A string that is
another vocabulary's word and only happens to spell a registry name (a designer's target
``"coning"``) is marked on its line with ``# lint-model: <why>`` (:data:`PRAGMA`; the reason
is required).

The registry names are read from the registries themselves (so a newly registered family,
structure, set or motion is covered at once); ``--names`` replaces them (the tests use it).

Usage::

    python tools/lint_model.py [--names a,b,...] [PATH ...]      # default: src/strapdown

Exit status 0 when clean, 1 with one line per finding (``path:line: rule: message``).
"""

from __future__ import annotations

import argparse
import ast
import sys
from collections.abc import Iterable, Iterator
from pathlib import Path

#: Longest function outside the numba kernels, in lines (``def`` to its last line).
MAX_LINES = 80

#: The model's own modules (relative to ``src/strapdown``): where registry names are
#: declared and dispatched on. Each family module answers for its own names.
MODEL_MODULES = frozenset({
    "algorithms/family.py",
    "algorithms/spec.py",
    "algorithms/structures.py",
    "algorithms/rotvec.py",
    "algorithms/rate.py",
    "algorithms/quaternion.py",
    "algorithms/coning.py",
})

#: Marks a comparison whose string is another vocabulary's word, with the reason after it.
PRAGMA = "# lint-model:"

#: Decorators that make a function a compiled kernel (exempt from the length rule).
KERNEL_DECORATORS = frozenset({"njit", "jit", "vectorize", "guvectorize", "cfunc",
                               "stencil", "generated_jit", "overload"})

#: Files outside the model allowed a rule, relative to ``src/strapdown``, with why
#: (``{"design/x.py": (frozenset({"name-dispatch"}), "why")}``). Empty since the designer
#: asks its own target, layout and form objects; an entry would be work left, not a licence.
ALLOWED: dict[str, tuple[frozenset[str], str]] = {}


def registry_names() -> frozenset[str]:
    """Every registered name: families, update structures, coefficient sets, motions."""
    from strapdown.algorithms import coning, rate, spec
    from strapdown.analysis import evaluate

    names: set[str] = set(spec.ALGORITHMS) | set(spec.STRUCTURES)
    names |= set(coning.coefficient_set_names()) | set(rate.COEFFICIENTS)
    names |= set(evaluate.MOTIONS)
    return frozenset(names)


def _relative(path: Path) -> str:
    """The path relative to the package (``algorithms/spec.py``), else as given."""
    parts = path.resolve().parts
    if "strapdown" in parts:
        i = len(parts) - 1 - parts[::-1].index("strapdown")
        return "/".join(parts[i + 1:])
    return path.as_posix()


def _strings(node: ast.expr) -> Iterator[str]:
    """The string constants a comparison operand holds (itself or its tuple/list/set items)."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        yield node.value
    elif isinstance(node, ast.Tuple | ast.List | ast.Set):
        for elt in node.elts:
            if isinstance(elt, ast.Constant) and isinstance(elt.value, str):
                yield elt.value


def _decorator_name(node: ast.expr) -> str:
    if isinstance(node, ast.Call):
        node = node.func
    if isinstance(node, ast.Attribute):
        return node.attr
    if isinstance(node, ast.Name):
        return node.id
    return ""


def _is_kernel(fn: ast.FunctionDef | ast.AsyncFunctionDef) -> bool:
    return any(_decorator_name(d) in KERNEL_DECORATORS for d in fn.decorator_list)


def _length(fn: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    """Lines from the ``def`` to the function's last line, its docstring left out (prose
    is not code: a well-documented function is not a long one)."""
    length = (fn.end_lineno or fn.lineno) - fn.lineno + 1
    first = fn.body[0] if fn.body else None
    if (isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant)
            and isinstance(first.value.value, str)):
        length -= (first.end_lineno or first.lineno) - first.lineno + 1
    return length


def _marked(lines: list[str], node: ast.AST) -> bool:
    """Whether a line of ``node`` carries :data:`PRAGMA` with a reason after it."""
    first = getattr(node, "lineno", 0)
    last = getattr(node, "end_lineno", None) or first
    for text in lines[first - 1:last]:
        _, found, why = text.partition(PRAGMA)
        if found and why.strip():
            return True
    return False


def check_source(source: str, rel: str, names: frozenset[str]) -> list[tuple[int, str, str]]:
    """``(line, rule, message)`` findings of one file's text (``rel``: its package path)."""
    tree = ast.parse(source, filename=rel)
    allowed = ALLOWED.get(rel, (frozenset(), ""))[0]
    dispatch_ok = rel in MODEL_MODULES or "name-dispatch" in allowed
    lines = source.splitlines()
    out: list[tuple[int, str, str]] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            length = _length(node)
            if (length > MAX_LINES and not _is_kernel(node)
                    and "long-function" not in allowed):
                out.append((node.lineno, "long-function",
                            f"{node.name} is {length} lines; at most {MAX_LINES} outside the "
                            "numba kernels (split it; a C template goes to a template file)"))
        if dispatch_ok:
            continue
        hits: list[str] = []
        if isinstance(node, ast.Compare):
            for operand in (node.left, *node.comparators):
                hits += [s for s in _strings(operand) if s in names]
        elif isinstance(node, ast.MatchValue):
            hits += [s for s in _strings(node.value) if s in names]
        if hits and _marked(lines, node):
            continue
        if hits:
            shown = ", ".join(repr(s) for s in dict.fromkeys(hits))
            out.append((node.lineno, "name-dispatch",
                        f"comparison against the registry name(s) {shown} outside the model "
                        "(ask the registered object for the fact instead)"))
    return sorted(out)


def python_files(paths: Iterable[Path]) -> Iterator[Path]:
    for p in paths:
        if p.is_dir():
            yield from sorted(q for q in p.rglob("*.py") if "__pycache__" not in q.parts)
        else:
            yield p


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("paths", nargs="*", type=Path, default=[Path("src/strapdown")])
    parser.add_argument("--names", help="comma-separated registry names (default: the "
                        "registries' own)")
    args = parser.parse_args(argv)
    names = (frozenset(n for n in args.names.split(",") if n) if args.names is not None
             else registry_names())
    findings = 0
    for path in python_files(args.paths):
        rel = _relative(path)
        for line, rule, msg in check_source(path.read_text(encoding="utf-8"), rel, names):
            print(f"{path}:{line}: {rule}: {msg}")
            findings += 1
    if findings:
        print(f"{findings} finding(s); see tools/lint_model.py for the rules", file=sys.stderr)
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())

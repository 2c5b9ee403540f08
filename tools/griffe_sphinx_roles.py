"""Griffe extension: the docstrings' Sphinx roles as mkdocstrings cross-references.

The docstrings are numpy style with Sphinx roles (``:func:`~strapdown.analysis.drift_rate```,
``:mod:`.rotvec```, ``:data:`REGISTRY```). Before mkdocstrings renders them, each role whose
target is an object of this package becomes an autorefs link (``[drift_rate][strapdown.
analysis.accuracy.drift_rate]``), resolved the way Sphinx does: the class, then the module,
then the enclosing packages, then the top-level package. A target outside the package
(``numpy.random.Generator``) becomes code. A target that names this package but exists
nowhere in it is a broken reference: griffe logs a warning, which fails ``mkdocs build
--strict``. ``:math:`x``` becomes ``$x$``-free code (no math renderer is configured).
"""

from __future__ import annotations

import functools
import re
from typing import Any

import griffe

ROOT = "strapdown"
_ROLE = re.compile(r":(?:py:)?(class|func|meth|mod|data|attr|obj|exc|const|math):`([^`]+)`")
_logger = griffe.get_logger("griffe_sphinx_roles")


def _walk(obj: griffe.Object):
    yield obj
    for member in obj.members.values():
        if isinstance(member, griffe.Alias):
            continue
        yield from _walk(member)


@functools.cache
def _lazy_exports() -> dict[str, str]:
    """``strapdown.NAME`` → its defining module (``import strapdown`` imports them lazily)."""
    import strapdown

    return {f"{ROOT}.{name}": f"{mod}.{name}" for name, mod in strapdown._EXPORTS.items()}


def _exists(pkg: griffe.Module, path: str) -> griffe.Object | griffe.Alias | None:
    if path == ROOT:
        return pkg
    path = _lazy_exports().get(path, path)
    if not path.startswith(ROOT + "."):
        return None
    try:
        return pkg[path[len(ROOT) + 1:]]
    except (KeyError, ValueError, griffe.AliasResolutionError, griffe.CyclicAliasError):
        return None


def _scopes(obj: griffe.Object) -> list[str]:
    """Where a bare name is looked up from *obj*: its class, module, packages, the root."""
    out, cur = [], obj if obj.kind in (griffe.Kind.CLASS, griffe.Kind.MODULE) else obj.parent
    while cur is not None:
        out.append(cur.path)
        cur = cur.parent
    return out


def _resolve(pkg: griffe.Module, obj: griffe.Object, target: str) -> str | None:
    if target.startswith("."):
        name = target.lstrip(".")
        candidates = [f"{scope}.{name}" for scope in _scopes(obj)]
    elif target.startswith(ROOT + ".") or target == ROOT:
        candidates = [target]
    else:
        candidates = [f"{scope}.{target}" for scope in _scopes(obj)]
    for path in candidates:
        found = _exists(pkg, path)
        if found is not None:
            return _public_path(found, _lazy_exports().get(path, path)) or ""
    return None


def _private(path: str) -> bool:
    return any(p.startswith("_") and not p.startswith("__") for p in path.split(".")[1:])


def _public_path(found: Any, path: str) -> str | None:
    """The identifier the site renders the object under: an alias's target (imported names
    are rendered where they are defined); None when it is not rendered (private; outside the
    package). The top-level exports defined in private modules are on the API index."""
    if isinstance(found, griffe.Alias):
        try:
            path = found.final_target.path
        except (griffe.AliasResolutionError, griffe.CyclicAliasError):
            return None
    if path.split(".")[0] != ROOT:
        return None
    if _private(path) and path not in _lazy_exports().values():
        return None
    return path


def _convert(pkg: griffe.Module, obj: griffe.Object, text: str) -> str:
    def repl(m: re.Match) -> str:
        role, body = m.group(1), m.group(2)
        if role == "math":
            return f"`{body}`"
        title = None
        named = re.fullmatch(r"(.+?)\s*<(.+)>", body)
        if named:
            title, body = named.group(1), named.group(2)
        nolink = body.startswith("!")
        tilde = body.startswith("~")
        target = re.sub(r"\s+", "", body.lstrip("!~"))  # a role wrapped over two lines
        bare = target.rstrip("()")
        shown = title or (bare.rsplit(".", 1)[-1] if tilde else bare.lstrip("."))
        shown = f"`{shown}()`" if role in ("func", "meth") and not title else f"`{shown}`"
        if nolink:
            return shown
        path = _resolve(pkg, obj, bare)
        if path == "":  # exists, but private: not on the site
            return shown
        if path is None:
            if bare.startswith(ROOT + ".") or bare.startswith("."):
                _logger.warning("%s: broken reference %s in the docstring of %s",
                                obj.relative_filepath, m.group(0), obj.path)
            return shown
        return f"[{shown}][{path}]"

    return _ROLE.sub(repl, text)


class SphinxRoles(griffe.Extension):
    """Rewrite Sphinx roles in every docstring of the package once it is loaded."""

    def on_package(self, *, pkg: griffe.Module, **kwargs: Any) -> None:
        if pkg.name != ROOT:
            return
        for obj in _walk(pkg):
            if obj.docstring is not None and ":" in obj.docstring.value:
                obj.docstring.value = _convert(pkg, obj, obj.docstring.value)

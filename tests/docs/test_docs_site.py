"""The reference site builds with no warning, lists the public API and every command, runs the
gallery, and a broken cross-reference fails it (``make docs``; ``mkdocs.yml``).

The build is ``mkdocs build --strict`` (every warning an error) into a temporary directory:
the same command as ``make docs``, so a broken link, anchor or ``[name][identifier]``
reference, a docstring role naming nothing in the package, or a gallery script or build-time
reproduction that fails, fails this test. It needs the ``docs`` extra (part of ``dev``).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("mkdocs", reason="the docs extra is not installed: pip install -e '.[docs]'")
pytest.importorskip("mkdocstrings", reason="the docs extra is not installed")
yaml = pytest.importorskip("yaml")

REPO = Path(__file__).resolve().parents[2]
ENV = dict(os.environ, NO_MKDOCS_2_WARNING="1", MPLBACKEND="Agg")


def _build(config: Path, site: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--config-file",
                           str(config), "--site-dir", str(site)], cwd=REPO, env=ENV,
                          capture_output=True, text=True, timeout=900)


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("site")
    proc = _build(REPO / "mkdocs.yml", out)
    warnings = [ln for ln in proc.stderr.splitlines() if "WARNING" in ln or "ERROR" in ln]
    assert proc.returncode == 0, ("mkdocs build --strict failed:\n" + "\n".join(warnings) +
                                  "\n" + proc.stderr[-3000:])
    assert not warnings, warnings
    return out


def _html(site: Path, page: str) -> str:
    return (site / page / "index.html").read_text("utf-8")


@pytest.mark.slow
@pytest.mark.parametrize(("page", "identifier"), [
    ("api/strapdown.algorithms.spec", "strapdown.algorithms.spec.AlgorithmSpec"),
    ("api/strapdown.ahrs.filter", "strapdown.ahrs.filter.ekf"),
    ("api/strapdown.io.readers", "strapdown.io.readers.read_imu"),
    ("api/strapdown.navigation.earth", "strapdown.navigation.earth.navigate"),
    ("api/strapdown.truth.motions", "strapdown.truth.motions.ClassicalConing"),
    ("api/strapdown.design.designer", "strapdown.design.designer.derive"),
    ("api", "strapdown._core.errors.InputError"),
])
def test_api_reference_lists(site, page, identifier):
    assert f'id="{identifier}"' in _html(site, page)


@pytest.mark.slow
def test_api_index_links_every_top_level_name(site):
    import strapdown

    html = _html(site, "api")
    for name, module in strapdown._EXPORTS.items():
        assert f"{module}.{name}" in html, name


@pytest.mark.slow
def test_cli_page_has_every_command(site):
    from strapdown.cli import COMMANDS

    html = _html(site, "cli")
    for module in COMMANDS:
        name = module.__name__.rsplit(".", 1)[1].replace("_", "-")
        assert f'id="strapdown-{name}"' in html, name
        assert f"usage: strapdown {name}" in html, name


@pytest.mark.slow
def test_gallery_ran_every_example(site):
    scripts = sorted((REPO / "examples").glob("*.py"))
    assert len(scripts) >= 2
    for script in scripts:
        html = _html(site, f"gallery/{script.stem}")
        assert "ran in" in html and "Output" in html, script.name
    assert list((site / "gallery").glob("coning_drift_*.png")), "the gallery drew no figure"


@pytest.mark.slow
def test_pages_are_in_the_site(site):
    for page in ("tutorial", "conventions", "algorithms", "reproductions", "references",
                 "reproductions/plaksiy2024/report"):
        assert (site / page / "index.html").is_file(), page
    assert (site / "search" / "search_index.json").is_file()


def test_a_broken_cross_reference_fails_the_build(tmp_path):
    """The site's own settings (strict, link validation, autorefs) on two planted errors: a
    link to a heading that does not exist and a reference to an identifier that does not."""
    config = yaml.safe_load((REPO / "mkdocs.yml").read_text("utf-8"))
    docs = tmp_path / "docs"
    docs.mkdir()
    (docs / "index.md").write_text("# Home\n\nSee [the frames](other.md#no-such-heading).\n")
    (docs / "other.md").write_text(
        "# Other\n\n## Frames\n\n[parse_spec][strapdown.algorithms.spec.parse_spec] and "
        "[a name][strapdown.algorithms.spec.no_such_name].\n\n"
        "::: strapdown.algorithms.spec.parse_spec\n")
    config.update(docs_dir=str(docs), site_dir=str(tmp_path / "site"))
    config.pop("hooks", None)
    config.pop("nav", None)
    plugin = next(p for p in config["plugins"] if isinstance(p, dict) and "mkdocstrings" in p)
    handler = plugin["mkdocstrings"]["handlers"]["python"]
    handler["paths"] = [str(REPO / "src")]
    handler["options"]["extensions"] = ["griffe_sphinx"]
    path = tmp_path / "mkdocs.yml"
    path.write_text(yaml.safe_dump(config), "utf-8")
    proc = _build(path, tmp_path / "site")
    assert proc.returncode != 0
    assert "no-such-heading" in proc.stderr
    assert re.search(r"strapdown\.algorithms\.spec\.no_such_name", proc.stderr), proc.stderr


def test_docstring_roles_become_references(caplog):
    """tools/griffe_sphinx_roles.py: a role naming an object of the package becomes a
    reference to where the site renders it; one naming nothing there is a warning (which
    fails the strict build); one outside the package is code."""
    import importlib.util
    import logging

    import griffe

    spec = importlib.util.spec_from_file_location("griffe_sphinx_roles",
                                                  REPO / "tools" / "griffe_sphinx_roles.py")
    roles = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(roles)
    pkg = griffe.load("strapdown", search_paths=[str(REPO / "src")])
    where = pkg["algorithms.spec"]
    convert = roles._convert
    assert convert(pkg, where, ":class:`AlgorithmSpec`") == (
        "[`AlgorithmSpec`][strapdown.algorithms.spec.AlgorithmSpec]")
    assert convert(pkg, where, ":mod:`.rotvec`") == "[`rotvec`][strapdown.algorithms.rotvec]"
    assert convert(pkg, where, ":func:`~strapdown.read_imu`") == (
        "[`read_imu()`][strapdown.io.readers.read_imu]")
    assert convert(pkg, where, ":class:`numpy.random.Generator`") == (
        "`numpy.random.Generator`")
    with caplog.at_level(logging.WARNING):
        assert convert(pkg, where, ":func:`strapdown.no_such_name`") == (
            "`strapdown.no_such_name()`")
    assert "broken reference" in caplog.text

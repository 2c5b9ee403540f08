"""Generated modules carry their own prefix on every type and macro (no bare ``real_t``),
so any set of them compiles into one program; otherwise the output is unchanged."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest
from golden_configs import CONFIGS

from c_harness import compiler
from strapdown.codegen.ahrs_c import generate_ahrs
from strapdown.codegen.export_c import AHRS_ALGORITHMS, ALGORITHMS, generate

GOLDEN = Path(__file__).parent / "golden"
STRICT = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-Wconversion"]
_NAV_CONSTANTS = "A|F|E2|OMEGA|GE|GK|GM"


def unprefix(text: str, name: str) -> str:
    """The generated text with the module-prefixed names put back to the unprefixed ones the
    exporter wrote before (``real_t``, the window macro ``W``, the ``SD_`` WGS-84 macros)."""
    up = name.upper()
    text = re.sub(rf"\b{name}_real\b", "real_t", text)
    text = re.sub(rf"\b{up}_W\(", "W(", text)
    return re.sub(rf"\b{up}_({_NAV_CONSTANTS})\b", r"SD_\1", text)


def _id(kw):
    return "-".join(str(v) for v in kw.values())


@pytest.mark.parametrize("kw", CONFIGS, ids=_id)
def test_only_the_prefixed_names_changed(kw):
    e = generate(**kw)
    folder = GOLDEN / kw.get("real", "double")
    assert unprefix(e.header, e.name) == (folder / f"{e.name}.h").read_text()
    assert unprefix(e.source, e.name) == (folder / f"{e.name}.c").read_text()


@pytest.mark.parametrize("kw", CONFIGS, ids=_id)
def test_no_unprefixed_type_or_macro(kw):
    e = generate(**kw)
    up = e.name.upper()
    for text in (e.header, e.source):
        assert not re.search(r"\breal_t\b", text)
        for macro in re.findall(r"#\s*define\s+(\w+)", text):
            assert macro.startswith(up + "_"), macro
        for typ in re.findall(r"typedef\s+(?:struct\s*\{[^}]*\}|[^;{]*?)\s*(\w+)\s*;",
                              text):
            assert typ.startswith(e.name + "_"), typ


def test_golden_covers_every_algorithm():
    # the AHRS is new (no old output to hold): its own tests, and the compile test below
    assert {kw["algorithm"] for kw in CONFIGS} == set(ALGORITHMS) - set(AHRS_ALGORITHMS)


#: AHRS modules: float and double, with and without magnetometer, and RK4 in float
AHRS = [{"real": r, "mag": m} for r in ("double", "float") for m in (True, False)] + [
    {"real": "float", "mag": True, "algorithm": "rk4"}]


@pytest.mark.parametrize("kw", AHRS, ids=_id)
def test_ahrs_has_no_unprefixed_type_or_macro(kw):
    e = generate_ahrs(200.0, **kw, name="my_ahrs")
    for text in (e.header, e.source):
        assert not re.search(r"\breal_t\b", text)
        for macro in re.findall(r"#\s*define\s+(\w+)", text):
            assert macro.startswith("MY_AHRS_"), macro
        for typ in re.findall(r"typedef\s+(?:struct\s*\{[^}]*\}|[^;{]*?)\s*(\w+)\s*;", text):
            assert typ.startswith("my_ahrs_"), typ


def test_float_and_double_modules_compile_together(tmp_path):
    # every golden configuration (each attitude algorithm and structure in float and in
    # double, three double nav modules), each under its own name, in one program
    mods = []
    for i, kw in enumerate(CONFIGS):
        e = generate(**{**kw, "name": f"m{i}_{kw['algorithm'].replace('-', '_')}"})
        (tmp_path / f"{e.name}.h").write_text(e.header)
        (tmp_path / f"{e.name}.c").write_text(e.source)
        mods.append(e)
    assert {e.real for e in mods} == {"float", "double"}
    ahrs = [generate_ahrs(100.0, **kw, name=f"a{i}_ahrs") for i, kw in enumerate(AHRS)]
    for e in ahrs:
        (tmp_path / f"{e.name}.h").write_text(e.header)
        (tmp_path / f"{e.name}.c").write_text(e.source)
    lines = [f'#include "{e.name}.h"' for e in [*mods, *ahrs]] + ["#include <stdio.h>", "",
                                                         "int main(void)", "{", "    int n = 0;"]
    for e in mods:
        r = f"{e.name}_real"
        lines.append("    {")
        lines.append(f"        {e.name}_state s;")
        lines.append(f"        const {r} q0[4] = {{1, 0, 0, 0}}, "
                     "x[3] = {0.001f, 0.002f, 0.003f};")
        if e.name.split("_", 1)[1] == "nav":
            lines.append(f"        const {r} p0[3] = {{0.8f, 0.2f, 100}}, v0[3] = {{1, 2, 3}};")
            lines.append(f"        {r} p[3], v[3], q[4];")
            lines.append("        int k;")
            lines.append(f"        {e.name}_init(&s, 0.01f, p0, v0, q0);")
            lines.append(f"        for (k = 0; k < 12; ++k) "
                         f"n += {e.name}_update(&s, x, x, p, v, q);")
        else:
            lines.append(f"        {r} q[4];")
            lines.append("        int k;")
            lines.append(f"        {e.name}_init(&s, q0);")
            lines.append(f"        for (k = 0; k < 12; ++k) n += {e.name}_update(&s, x, q);")
            lines.append(f"        {e.name}_reset(&s);")
        lines.append(f"        if (sizeof s != {e.name}_state_size()) return 1;")
        lines.append("    }")
    for e in ahrs:
        r = f"{e.name}_real"
        lines += ["    {", f"        static {e.name}_state s;", f"        {r} q[4];",
                  f"        const {r} g[3] = {{0.01f, 0, 0}}, a[3] = {{0, 0, 9.8f}}, "
                  "m[3] = {0, 20, -40};",
                  "        int k;", f"        {e.name}_init(&s);",
                  f"        for (k = 0; k < 120; ++k) n += {e.name}_update(&s, g, a, m, q) == 0;",
                  f"        if (sizeof s != {e.name}_state_size()) return 1;", "    }"]
    lines += ['    printf("%d\\n", n);', "    return 0;", "}", ""]
    (tmp_path / "all.c").write_text("\n".join(lines))
    exe = tmp_path / "all"
    res = subprocess.run([compiler(), *STRICT, "-o", str(exe), str(tmp_path / "all.c"),
                          *(str(tmp_path / f"{e.name}.c") for e in [*mods, *ahrs]), "-lm"],
                         capture_output=True, text=True, cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    run = subprocess.run([str(exe)], capture_output=True, text=True)
    assert run.returncode == 0 and int(run.stdout) > 0

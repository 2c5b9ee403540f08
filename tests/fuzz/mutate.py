"""Seeded mutations of valid files (the fuzz campaign's generated inputs).

Binary formats get bit flips, interesting bytes and machine words (0, −1, 2³¹ − 1, 2³², …)
written over the file, truncation, deleted, duplicated and spliced chunks — a flipped byte
in an uncompressed ``.mat`` is what crashed scipy's reader. Text formats (CSV, TOML) get
token-level mutations as well: extreme numbers (1e308, 5e-324, nan, inf, 1e999), wrong
types, other delimiters and line ends, a BOM, very long cells, deep nesting, lines dropped
or repeated. Every mutation is drawn from a :class:`numpy.random.Generator`, so a run is
reproducible from its seed.
"""

from __future__ import annotations

import struct

import numpy as np

__all__ = ["mutate"]

_BYTES = (0x00, 0xFF, 0x7F, 0x80, 0x01, 0x0A, 0x22, 0x5B)
_WORDS = (0, 1, 0xFFFFFFFF, 0x7FFFFFFF, 0x80000000, 0xFFFFFFFE, 64, 4096, 0x10000, 2**24,
          12, 14, 15, 9, 6)
_NUMBERS = ("1e308", "-1e308", "nan", "inf", "-inf", "5e-324", "0", "-0.0", "1e-320",
            "1e999", "", "x", "1,5", "0x10", "1e", "--1", "9" * 400, "1e+308", "2.5",
            "-7", "3e5")
_TOML_VALUES = ('"a"', "[]", "{}", "nan", "inf", "-1", "0", "1e308", "true", "[1, 2]",
                "[[1], [2]]", '"rotvec:N=99"', "{a = 1}", "1979-05-27", '"gyro.bias"',
                "[" * 300 + "]" * 300, "1e-320", "-0.0", '["a", 1]')


def _binary(data: bytes, rng: np.random.Generator, seeds: list[bytes]) -> bytes:
    b = bytearray(data)
    op = int(rng.integers(8))
    if not b:
        return bytes(rng.integers(0, 256, int(rng.integers(1, 64)), dtype=np.uint8))
    n = len(b)
    if op == 0:  # bit flips
        for _ in range(int(rng.integers(1, 9))):
            i = int(rng.integers(n))
            b[i] ^= 1 << int(rng.integers(8))
    elif op == 1:  # interesting bytes
        for _ in range(int(rng.integers(1, 5))):
            b[int(rng.integers(n))] = _BYTES[int(rng.integers(len(_BYTES)))]
    elif op == 2 and n >= 8:  # an interesting machine word, aligned (tags, sizes, dims)
        i = int(rng.integers(n // 4)) * 4
        w = _WORDS[int(rng.integers(len(_WORDS)))]
        b[i:i + 4] = struct.pack("<I" if rng.random() < 0.8 else ">I", w)
    elif op == 3:  # truncate
        return bytes(b[:int(rng.integers(n))])
    elif op == 4:  # delete a chunk
        i = int(rng.integers(n))
        del b[i:i + int(rng.integers(1, 256))]
    elif op == 5:  # duplicate a chunk
        i = int(rng.integers(n))
        k = int(rng.integers(1, 512))
        j = int(rng.integers(n))
        b[j:j] = b[i:i + k]
    elif op == 6:  # splice with another seed
        other = seeds[int(rng.integers(len(seeds)))]
        cut = int(rng.integers(n))
        return bytes(b[:cut]) + other[int(rng.integers(max(len(other), 1))):]
    else:  # several flips in a row of bytes (a corrupted sector)
        i = int(rng.integers(n))
        for j in range(i, min(n, i + int(rng.integers(1, 32)))):
            b[j] = int(rng.integers(256))
    return bytes(b)


def _csv(text: str, rng: np.random.Generator) -> str:
    lines = text.split("\n")
    if len(lines) < 2:
        lines.append("0,1,2,3")
    op = int(rng.integers(12))
    if op <= 3:  # an extreme number somewhere
        k = int(rng.integers(1, len(lines)))
        cells = lines[k].split(",")
        if cells and cells[0]:
            cells[int(rng.integers(len(cells)))] = _NUMBERS[int(rng.integers(len(_NUMBERS)))]
            lines[k] = ",".join(cells)
    elif op == 4:  # the header
        cells = lines[0].split(",")
        choice = ("t[ms]", "gx[deg/s]", "gx[furlong]", "", "time", "gx", "t", "x" * 70_000,
                  "gy[rad/s]", "ax[g]", "mx")
        cells[int(rng.integers(len(cells)))] = choice[int(rng.integers(len(choice)))]
        lines[0] = ",".join(cells)
    elif op == 5:
        sep = (";", "\t", "|", " ", ",,")[int(rng.integers(5))]
        lines = [ln.replace(",", sep) for ln in lines]
    elif op == 6:
        return "\ufeff" + "\r\n".join(lines)
    elif op == 7:  # drop or repeat lines
        k = int(rng.integers(len(lines)))
        if rng.random() < 0.5:
            del lines[k:k + int(rng.integers(1, 40))]
        else:
            lines[k:k] = [lines[k]] * int(rng.integers(1, 5))
    elif op == 8:  # a ragged row
        k = int(rng.integers(1, len(lines)))
        lines[k] = lines[k].rsplit(",", 1)[0] if rng.random() < 0.5 else lines[k] + ",1"
    elif op == 9:  # scale a time or a rate column
        factor = ("1e300", "1e-300", "-1", "0")[int(rng.integers(4))]
        col = int(rng.integers(4))
        out = [lines[0]]
        for ln in lines[1:]:
            cells = ln.split(",")
            if len(cells) > col and cells[col]:
                try:
                    cells[col] = repr(float(cells[col]) * float(factor))
                except ValueError:
                    pass
            out.append(",".join(cells))
        lines = out
    elif op == 10:  # random unicode or control characters
        k = int(rng.integers(len(lines)))
        junk = ("\x00", "\u2028", "é", "\x1b[2J", '"', "'", "#", "\\")
        lines[k] += junk[int(rng.integers(len(junk)))]
    else:
        return "\n".join(lines[: int(rng.integers(3))])
    return "\n".join(lines)


def _toml(text: str, rng: np.random.Generator) -> str:
    lines = text.split("\n")
    op = int(rng.integers(6))
    assign = [i for i, ln in enumerate(lines) if " = " in ln]
    if op <= 2 and assign:  # a value of another type or range
        k = assign[int(rng.integers(len(assign)))]
        key = lines[k].split(" = ", 1)[0]
        lines[k] = f"{key} = {_TOML_VALUES[int(rng.integers(len(_TOML_VALUES)))]}"
    elif op == 3:  # a new key, in a section or at the top
        keys = ("gyro", "grid", "subsamples", "coefficients", "structure", "precision",
                "alpha", "step", "krylov_rates", "bias", "misalignment", "saturation",
                "quantization", "gm_tau", "seed", '"gyro.white_noise"', "cone_rate_hz")
        k = int(rng.integers(len(lines) + 1))
        lines.insert(k, f"{keys[int(rng.integers(len(keys)))]} = "
                        f"{_TOML_VALUES[int(rng.integers(len(_TOML_VALUES)))]}")
    elif op == 4:  # a grid that multiplies
        n = int(rng.integers(1, 2000))
        lines.append(f"[grid]\nduration = [{', '.join(str(0.1 + i) for i in range(n))}]")
    else:
        k = int(rng.integers(len(lines)))
        del lines[k]
    return "\n".join(lines)


def mutate(data: bytes, fmt: str, rng: np.random.Generator, seeds: list[bytes]) -> bytes:
    """One mutation of ``data`` (a file of format ``fmt``); text formats get a text-level
    mutation three times in four, else a byte-level one."""
    if fmt in ("csv", "toml") and rng.random() < 0.75:
        text = data.decode("utf-8", "replace")
        return (_csv(text, rng) if fmt == "csv" else _toml(text, rng)).encode(
            "utf-8", "surrogatepass")
    out = _binary(data, rng, seeds)
    if rng.random() < 0.3:  # a second mutation on top
        out = _binary(out, rng, seeds)
    return out

# SPDX-License-Identifier: GPL-3.0-or-later
"""One PLY reader for the mesh checks and the point files (no bpy).

read(path) parses and validates the header (format, elements with their
counts and properties), checks the claimed size against the file's size
before anything is allocated, and reads every element into numpy arrays:
a scalar property is a column of `count` values, a list property a List
(lengths, values) with the values of all rows one after another. ASCII rows
remember their line numbers for messages.

PlyError messages say what is wrong and what to do but not the file's name;
the callers put the file (and option) in front.
"""

import os
import struct
from dataclasses import dataclass, field

import numpy as np

TYPES = {"char": "i1", "uchar": "u1", "short": "i2", "ushort": "u2", "int": "i4", "uint": "u4",
         "float": "f4", "double": "f8", "int8": "i1", "uint8": "u1", "int16": "i2", "uint16": "u2",
         "int32": "i4", "uint32": "u4", "float32": "f4", "float64": "f8"}
FORMATS = {"ascii": None, "binary_little_endian": "<", "binary_big_endian": ">"}
FIX = "fix or re-export the file"


class PlyError(ValueError):
    """The PLY file is malformed; the message says what and the fix, not the file."""


@dataclass
class Property:
    name: str
    type: str  # numpy type code, e.g. "f4"
    count_type: str = None  # list properties: the numpy type of the length


@dataclass
class Element:
    name: str
    count: int
    line: int  # of the element line in the header
    properties: list = field(default_factory=list)


@dataclass
class List:
    lengths: np.ndarray  # one per row
    values: np.ndarray  # all rows' values, concatenated

    def rows(self):
        """The row of each value."""
        return np.repeat(np.arange(len(self.lengths)), self.lengths)


@dataclass
class Ply:
    format: str
    elements: list
    header_bytes: int
    data: dict = field(default_factory=dict)  # element name -> {property name -> column or List}
    lines: dict = field(default_factory=dict)  # ASCII: element name -> line number of each row

    def element(self, name):
        return next((e for e in self.elements if e.name == name), None)


def is_ply(path):
    with open(path, "rb") as f:
        return f.readline().strip() == b"ply"


def read(path):
    """The header and all elements of a PLY file; PlyError if it is malformed."""
    with open(path, "rb") as f:
        ply, lines = read_header(f)
        size = os.fstat(f.fileno()).st_size
        _check_size(ply, size - ply.header_bytes)
        rest = f.read()
    if ply.format == "ascii":
        _read_ascii(ply, rest, lines + 1)
    else:
        _read_binary(ply, rest)
    return ply


def read_header(f):
    """(Ply without data, number of header lines) from a file open at its start."""
    first = f.readline()
    if first.strip() != b"ply":
        raise PlyError("not a PLY file (its first line is not 'ply'); give a PLY file or " + FIX)
    fmt, elements, number, consumed = None, [], 1, len(first)
    while True:
        raw = f.readline()
        number += 1
        consumed += len(raw)
        words = raw.decode("ascii", "replace").split()
        key = words[0] if words else ""
        if key == "end_header":
            break
        if not raw.endswith(b"\n"):  # the end of the file
            raise PlyError("the PLY header has no end_header line (the file is cut short or not a PLY file); " + FIX)
        if key == "format":
            if len(words) != 3 or words[1] not in FORMATS:
                raise PlyError(f"header line {number}: unknown PLY format '{' '.join(words[1:])}' (ascii, "
                               f"binary_little_endian or binary_big_endian); {FIX}")
            fmt = words[1]
        elif key == "element":
            elements.append(_element(words, number))
        elif key == "property":
            if not elements:
                raise PlyError(f"header line {number}: a property before any element; {FIX}")
            _add_property(elements[-1], words, number)
        elif key not in ("comment", "obj_info", ""):
            shown = raw.strip()[:40].decode("ascii", "backslashreplace")
            raise PlyError(f"header line {number}: unknown header line '{shown}' (is end_header missing?); {FIX}")
    if fmt is None:
        raise PlyError(f"the PLY header has no format line; {FIX}")
    return Ply(fmt, elements, consumed), number


def _element(words, number):
    if len(words) != 3:
        raise PlyError(f"header line {number}: an element line is 'element NAME COUNT'; {FIX}")
    if not words[2].isdigit():
        raise PlyError(f"header line {number}: the count of element '{words[1]}' is '{words[2]}', not a "
                       f"non-negative integer; {FIX}")
    return Element(words[1], int(words[2]), number)


def _add_property(element, words, number):
    is_list = len(words) > 1 and words[1] == "list"
    if len(words) != (5 if is_list else 3):
        raise PlyError(f"header line {number}: a property line is 'property TYPE NAME' or 'property list "
                       f"COUNT_TYPE TYPE NAME'; {FIX}")
    types = words[2:4] if is_list else words[1:2]
    for t in types:
        if t not in TYPES:
            raise PlyError(f"header line {number}: unknown property type '{t}' (use one of "
                           f"{', '.join(TYPES)}); {FIX}")
    name = words[-1]
    if any(p.name == name for p in element.properties):
        raise PlyError(f"header line {number}: element '{element.name}' has two properties named '{name}'; {FIX}")
    if is_list and TYPES[words[2]][0] == "f":
        raise PlyError(f"header line {number}: the list '{name}' has its length as '{words[2]}'; a length "
                       f"must be an integer type (e.g. uchar or int); {FIX}")
    element.properties.append(Property(name, TYPES[types[-1]], TYPES[words[2]] if is_list else None))


def _check_size(ply, available):
    """Before reading: each row takes at least its fixed-size part (a list at
    least its length), an ASCII row at least a value and its line end."""
    least = 0
    for e in ply.elements:
        if not e.properties:
            continue
        if ply.format == "ascii":
            least += 2 * e.count
        else:
            least += e.count * sum(np.dtype(p.count_type or p.type).itemsize for p in e.properties)
        if least > available:
            raise PlyError(f"the header claims {e.count} {e.name} rows, at least {least} bytes of data, but the file "
                           f"has only {available} bytes after its header: it is cut short or its header is wrong; "
                           + FIX)


def _read_ascii(ply, rest, first_line):
    rows = [(n, line.split()) for n, line in enumerate(rest.split(b"\n"), first_line) if line.strip()]
    at = 0
    for e in ply.elements:
        chunk = rows[at:at + e.count]
        if len(chunk) < e.count:
            last = rows[-1][0] if rows else first_line - 1
            raise PlyError(f"the file ends at line {last}, after {len(chunk)} of its {e.count} {e.name} rows: it "
                           f"is cut short; {FIX}")
        at += e.count
        ply.lines[e.name] = np.array([n for n, _ in chunk], np.int64)
        if all(p.count_type is None for p in e.properties):
            ply.data[e.name] = _ascii_table(e, chunk)
        else:
            ply.data[e.name] = _ascii_rows(e, chunk)


def _ascii_table(e, chunk):
    """Rows of scalar properties only: one conversion for all of them."""
    k = len(e.properties)
    for n, words in chunk:
        if len(words) != k:
            raise PlyError(f"line {n}: {len(words)} values for a {e.name} row of {k} properties "
                           f"({' '.join(p.name for p in e.properties)}); {FIX}")
    try:
        table = np.array([w for _, w in chunk], np.float64).reshape(len(chunk), k)
    except ValueError:
        n, word = next((n, x) for n, w in chunk for x in w if not _is_number(x))
        raise PlyError(f"line {n}: '{word.decode('ascii', 'replace')}' is not a number; {FIX}") from None
    return {p.name: table[:, i] for i, p in enumerate(e.properties)}


def _is_number(word):
    try:
        float(word)
        return True
    except ValueError:
        return False


def _ascii_rows(e, chunk):
    """Rows with list properties, one at a time."""
    columns = {p.name: [] for p in e.properties}
    lengths = {p.name: [] for p in e.properties if p.count_type}
    for n, words in chunk:
        at = 0
        for p in e.properties:
            try:
                if p.count_type is None:
                    columns[p.name].append(float(words[at]))
                    at += 1
                    continue
                length = int(words[at])
                if length < 0:
                    raise ValueError
                values = words[at + 1:at + 1 + length]
                if len(values) != length:
                    raise IndexError
                parse = float if p.type[0] == "f" else int
                columns[p.name] += [parse(v) for v in values]
                lengths[p.name].append(length)
                at += 1 + length
            except IndexError:
                raise PlyError(f"line {n}: the {e.name} row ends before its '{p.name}'; {FIX}") from None
            except ValueError:
                raise PlyError(f"line {n}: the {e.name} row's '{p.name}' is not a length and that many "
                               f"{'numbers' if p.type[0] == 'f' else 'integers'}; {FIX}") from None
        if at != len(words):
            raise PlyError(f"line {n}: {len(words) - at} values left over at the end of the {e.name} row; {FIX}")
    return {p.name: (List(np.array(lengths[p.name], np.int64), np.array(columns[p.name], p.type))
                     if p.count_type else np.array(columns[p.name], np.float64)) for p in e.properties}


def _read_binary(ply, rest):
    order = FORMATS[ply.format]
    at = 0
    for e in ply.elements:
        if all(p.count_type is None for p in e.properties):
            dtype = np.dtype([(p.name, order + p.type) for p in e.properties])
            _need(e, at + dtype.itemsize * e.count, len(rest))
            table = np.frombuffer(rest, dtype, e.count, at)
            ply.data[e.name] = {p.name: table[p.name] for p in e.properties}
            at += dtype.itemsize * e.count
        else:
            ply.data[e.name], at = _binary_lists(e, rest, at, order)


def _need(e, end, size):
    if end > size:
        raise PlyError(f"the file ends within its {e.count} {e.name} rows ({end - size} bytes missing): it is cut "
                       f"short; {FIX}")


def _binary_lists(e, rest, at, order):
    """Rows with lists: all at once when the first row's lengths hold for all
    (e.g. all triangles), else one row at a time."""
    if e.count == 0:
        return {p.name: List(np.zeros(0, np.int64), np.zeros(0, p.type)) if p.count_type
                else np.zeros(0, np.float64) for p in e.properties}, at
    fields, offset = [], at
    for p in e.properties:
        if p.count_type is None:
            fields.append((p.name, order + p.type))
            offset += np.dtype(p.type).itemsize
            continue
        _need(e, offset + np.dtype(p.count_type).itemsize, len(rest))
        length = int(np.frombuffer(rest, order + p.count_type, 1, offset)[0])
        fields += [(p.name + "#", order + p.count_type), (p.name, order + p.type, (max(length, 0),))]
        offset += np.dtype(p.count_type).itemsize + max(length, 0) * np.dtype(p.type).itemsize
    dtype = np.dtype(fields)
    end = at + dtype.itemsize * e.count
    if end <= len(rest):
        table = np.frombuffer(rest, dtype, e.count, at)
        if all(np.all(table[p.name + "#"] == table.dtype[p.name].shape[0]) for p in e.properties if p.count_type):
            return {p.name: List(table[p.name + "#"].astype(np.int64), table[p.name].reshape(-1)) if p.count_type
                    else table[p.name] for p in e.properties}, end
    return _binary_rows(e, rest, at, order)


def _binary_rows(e, rest, at, order):
    columns = {p.name: [] for p in e.properties}
    lengths = {p.name: [] for p in e.properties if p.count_type}
    unpack = {t: struct.Struct(order + t) for t in ("b", "B", "h", "H", "i", "I", "f", "d")}
    code = {"i1": "b", "u1": "B", "i2": "h", "u2": "H", "i4": "i", "u4": "I", "f4": "f", "f8": "d"}
    size = len(rest)
    for row in range(e.count):
        for p in e.properties:
            s = unpack[code[p.count_type or p.type]]
            _need(e, at + s.size, size)
            (value,) = s.unpack_from(rest, at)
            at += s.size
            if p.count_type is None:
                columns[p.name].append(value)
                continue
            if value < 0:
                raise PlyError(f"{e.name} row {row}: the list '{p.name}' has a negative length ({value}); {FIX}")
            width = np.dtype(p.type).itemsize * value
            _need(e, at + width, size)
            columns[p.name].append(np.frombuffer(rest, order + p.type, value, at))
            lengths[p.name].append(value)
            at += width
    return {p.name: (List(np.array(lengths[p.name], np.int64), np.concatenate(columns[p.name]).astype(p.type))
                     if p.count_type else np.array(columns[p.name], np.float64)) for p in e.properties}, at

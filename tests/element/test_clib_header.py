"""The ctypes layer (fmu_src/_clib.py) against the C headers it mirrors (fmu_src/core/iwan.h,
iwan2d.h).

The prototypes and struct fields are parsed from the headers, so a changed signature or
field fails here instead of corrupting memory at run time.
"""
from __future__ import annotations

import ctypes as ct
import re
from pathlib import Path

import pytest

from fmu_src import _clib

HEADER = Path(_clib.__file__).resolve().parent / "core" / "iwan.h"
HEADER2 = HEADER.with_name("iwan2d.h")
HEADER3 = HEADER.with_name("contact_point.h")
_TEXT = re.sub(r"/\*.*?\*/", " ", HEADER.read_text() + HEADER2.read_text() + HEADER3.read_text(),
               flags=re.S)

#: C type (as written in iwan.h, const dropped) -> the ctypes type _clib must use.
_SCALARS = {"double": ct.c_double, "size_t": ct.c_size_t, "int": ct.c_int, "iwan_fit": ct.c_int,
            "iwan_status": ct.c_int, "int32_t": ct.c_int32}
_POINTERS = {"iwan_model": ct.POINTER(_clib.Model), "iwan_output": ct.POINTER(_clib.Output),
             "iwan2_state": ct.POINTER(_clib.State2), "iwan2_output": ct.POINTER(_clib.Output2),
             "cpoint_model": ct.POINTER(_clib.CPointModel), "cpoint_state": ct.POINTER(_clib.CPointState),
             "cpoint_output": ct.POINTER(_clib.CPointOutput),
             "int": ct.POINTER(ct.c_int), "size_t": ct.POINTER(ct.c_size_t),
             "int32_t": ct.POINTER(ct.c_int32)}


def prototypes() -> dict[str, tuple[str, list[str]]]:
    """name -> (return type, [parameter types]) of every function the headers declare."""
    out = {}
    decl = r"\n((?:const\s+)?\w+\s*\**)\s*((?:iwan2?|cpoint)_\w+)\s*\(([^)]*)\)\s*;"
    for ret, name, params in re.findall(decl, _TEXT):
        types = []
        for p in params.split(","):
            words = p.replace("*", " * ").replace("const", " ").split()
            types.append(" ".join(words[:-1]))      # drop the parameter name
        out[name] = (ret.replace(" ", ""), types)
    return out


def _expected(c_type: str, name: str, position: int):
    base, stars = c_type.replace(" *", "").strip(), c_type.count("*")
    if stars == 2:  # an array of pointers (iwan_periodic_jac_many: models, EN)
        return ct.POINTER(_expected(c_type[:c_type.rindex("*")].strip(), name, position))
    if stars == 0:
        return _SCALARS[base]
    if base == "double":    # an array, or a scalar output passed by reference
        return ct.POINTER(ct.c_double)
    if base == "iwan_state":  # one state, or a batch of states (iwan_step_batch)
        return ct.POINTER(_clib.State)
    return _POINTERS[base]


def test_every_header_function_is_declared_once_with_matching_types():
    protos = prototypes()
    assert len(protos) == 28 and set(protos) == set(_clib.FUNCTIONS)
    for name, (ret, params) in protos.items():
        restype, argtypes = _clib.FUNCTIONS[name]
        assert restype is (ct.c_char_p if ret == "constchar*" else _SCALARS[ret]), name
        assert len(argtypes) == len(params), name
        for i, (c_type, py_type) in enumerate(zip(params, argtypes)):
            want = _expected(c_type, name, i)
            assert py_type is want, f"{name} argument {i}: C {c_type!r} declared as {py_type}"
        fn = getattr(_clib.lib, name)
        assert fn.argtypes == argtypes and fn.restype is restype


def _struct_fields(tag: str) -> list[tuple[str, str, int]]:
    body = re.search(r"typedef struct \{([^}]*)\}\s*" + tag + ";", _TEXT).group(1)
    fields = []
    sizes = {"": 1, "2": 2, "3": 3, "4": 4, "9": 9, "IWAN_MAX_SLIDERS": _clib.MAX_SLIDERS,
             "2 * IWAN_MAX_SLIDERS": 2 * _clib.MAX_SLIDERS, "CPOINT_MAX_NORMAL": _clib.MAX_NORMAL}
    for c_type, name, size in re.findall(r"(\w+)\s+(\w+)(?:\[([\w *]+)\])?;", body):
        fields.append((c_type, name, sizes[size]))
    return fields


@pytest.mark.parametrize("tag, struct", [("iwan_model", _clib.Model), ("iwan_state", _clib.State),
                                         ("iwan_output", _clib.Output), ("iwan2_state", _clib.State2),
                                         ("iwan2_output", _clib.Output2),
                                         ("cpoint_model", _clib.CPointModel),
                                         ("cpoint_state", _clib.CPointState),
                                         ("cpoint_output", _clib.CPointOutput)])
def test_structs_mirror_the_header_field_by_field(tag, struct):
    c_fields = _struct_fields(tag)
    assert [n for _, n, _ in c_fields] == [n for n, _ in struct._fields_]
    nested = {"iwan_model": _clib.Model, "iwan2_state": _clib.State2}
    for (c_type, name, size), (_, py_type) in zip(c_fields, struct._fields_):
        if c_type in nested:
            assert py_type is nested[c_type], f"{tag}.{name}"
            continue
        want = _SCALARS[c_type] if size == 1 else _SCALARS[c_type] * size
        assert py_type == want or (size > 1 and py_type._type_ is _SCALARS[c_type]
                                   and py_type._length_ == size), f"{tag}.{name}"


def test_constants_and_numpy_view_match_the_header():
    assert f"#define IWAN_MAX_SLIDERS {_clib.MAX_SLIDERS} " in HEADER.read_text()
    assert f"#define IWAN_STATE_VERSION {_clib.STATE_VERSION} " in HEADER.read_text()
    assert f"#define IWAN2_STATE_VERSION {_clib.STATE2_VERSION} " in HEADER2.read_text()
    assert f"#define CPOINT_MAX_NORMAL {_clib.MAX_NORMAL} " in HEADER3.read_text()
    assert f"#define CPOINT_STATE_VERSION {_clib.CPOINT_STATE_VERSION} " in HEADER3.read_text()
    assert _clib.STATE_DTYPE.itemsize == ct.sizeof(_clib.State)
    for name, _ in _clib.State._fields_:
        assert _clib.STATE_DTYPE.fields[name][1] == getattr(_clib.State, name).offset


def test_typed_pointers_refuse_the_wrong_array():
    import numpy as np

    with pytest.raises(TypeError, match="float64"):
        _clib.arr(np.zeros(3, dtype=np.float32))
    with pytest.raises(TypeError, match="contiguous"):
        _clib.arr(np.zeros((3, 2))[:, 0])
    with pytest.raises(TypeError, match="STATE_DTYPE|void|float64"):
        _clib.arr(np.zeros(3), _clib.StateArray)
    assert _clib.arr(None) is None
    with pytest.raises(ct.ArgumentError):          # ctypes refuses an untyped address
        _clib.lib.iwan_series(None, None, 1, 12345, None, None, None, None, None)


def test_element_modules_do_not_import_each_other_both_ways():
    src = Path(_clib.__file__).resolve().parent
    batch = (src / "element_batch.py").read_text()
    assert "from .element import" not in batch and "fmu_src.element import" not in batch

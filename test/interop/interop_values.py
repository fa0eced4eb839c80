"""Known values of the interop test service (robdef/experimental.interop_test.robdef).

Shared by official_service.py (which serves and accepts them) and official_client.py (which asserts
them). Everything here is deterministic: the same call always builds equal values.

Per read/write property there are two values:
  A = initial value, returned by a get after reset();
  B = second value; a set is accepted when the value equals A or B, anything else is rejected by the
      service with RobotRaconteur.InvalidArgument (so the service checks what the client encoded).

Values are built through a `Factory`, because structs, pods and namedarrays must be created from the
type information of a node (service side) or of a client connection (client side).

`deep_equal(a, b)` compares values the way the official Python mapping returns them (robdef.md §17.1):
numbers by their bits (so -0.0, NaN and subnormals are checked exactly), numpy arrays by dtype, shape
and bytes, structs by class name and every field, VarValue by type string and data.
"""

import math
import struct

import numpy as np

SERVICE = "experimental.interop_test"
SERVICE_NAME = "interop"  # name the service is registered under


def qn(short):
    """Qualified type name."""
    return SERVICE + "." + short


# Text with multi-byte UTF-8 of every length (2, 3 and 4 bytes), quotes, backslash and control chars.
UTF8_TEXT = "Gr\u00fc\u00dfe, \u4e16\u754c! \U0001F916 \"quoted\" \\ tab\t newline\n end"

# Color enum (robdef): red = 0, green = 1, blue = 0x10, minus = -5
COLOR = {"red": 0, "green": 1, "blue": 16, "minus": -5}

F32_MAX = float(np.finfo(np.float32).max)
F32_TINY_SUBNORMAL = float(np.float32(1.401298464324817e-45))  # smallest positive float32


def f32(x):
    """The Python float equal to the nearest float32 (so single values compare exactly)."""
    return float(np.float32(x))


class Factory:
    """Creates structs/pods/namedarrays from a node (service side) or a connection (client side)."""

    def __init__(self, RR, RRN, obj=None):
        self.RR = RR
        self.RRN = RRN
        self.obj = obj
        self._dtypes = {}

    def struct(self, short, **fields):
        if self.obj is None:
            s = self.RRN.NewStructure(qn(short))
        else:
            s = self.RRN.NewStructure(qn(short), self.obj)
        for k, v in fields.items():
            if not hasattr(s, k):
                raise AttributeError("%s has no field %s" % (short, k))
            setattr(s, k, v)
        return s

    def pod_dtype(self, short):
        key = ("pod", short)
        if key not in self._dtypes:
            if self.obj is None:
                self._dtypes[key] = self.RRN.GetPodDType(qn(short))
            else:
                self._dtypes[key] = self.RRN.GetPodDType(qn(short), self.obj)
        return self._dtypes[key]

    def na_dtype(self, short):
        key = ("na", short)
        if key not in self._dtypes:
            if self.obj is None:
                self._dtypes[key] = self.RRN.GetNamedArrayDType(qn(short))
            else:
                self._dtypes[key] = self.RRN.GetNamedArrayDType(qn(short), self.obj)
        return self._dtypes[key]

    def var(self, data, typestr):
        return self.RR.VarValue(data, typestr)


# ---------------------------------------------------------------------------------------------------
# Building blocks


def inner(f, i, label=None, values=None):
    if label is None:
        label = "inner %d \u00e9" % i
    if values is None:
        values = np.array([i, i + 0.5, -i], dtype=np.float64)
    return f.struct("Inner", id=i, label=label, values=np.asarray(values, dtype=np.float64))


def test_pods(f, n, seed=0):
    """n TestPod records with distinct, exactly representable contents."""
    a = np.zeros((n,), dtype=f.pod_dtype("TestPod"))
    for k in range(n):
        s = seed + k
        a[k]["x"] = 1.25 * (s + 1)
        a[k]["arr"] = [s, -s, 2147483647, -2147483648]
        blen = (s % 6) + 1  # bounded uint8[6-]: 1..6 items used; unused slots stay 0
        a[k]["bounded"]["len"] = blen
        a[k]["bounded"]["array"][:blen] = [(s * 7 + j) % 256 for j in range(blen)]
        a[k]["inner"]["a"] = -32768 + s
        a[k]["inner"]["b"] = [0.5, -0.5, s]
        for j in range(2):
            a[k]["inners"][j]["a"] = 100 * j + s
            a[k]["inners"][j]["b"] = [j, j + s, -1.0]
        a[k]["vec"]["x"] = 1.0 + s
        a[k]["vec"]["y"] = -2.0
        a[k]["vec"]["z"] = 0.125
        a[k]["c"] = complex(s, -0.75)
        a[k]["md"] = np.array([[1.0, 2.0], [3.0, 4.0 + s]])
    return a


def vec3s(f, n, seed=0):
    a = np.zeros((n,), dtype=f.na_dtype("Vec3"))
    for k in range(n):
        s = seed + k
        a[k]["x"] = s + 0.5
        a[k]["y"] = -s
        a[k]["z"] = 1e-300 * (s + 1)
    return a


def poses(f, n, seed=0):
    a = np.zeros((n,), dtype=f.na_dtype("Pose"))
    for k in range(n):
        s = seed + k
        a[k]["position"]["x"] = s
        a[k]["position"]["y"] = s * 2.0
        a[k]["position"]["z"] = -s
        a[k]["orientation"] = [1.0, 0.0, 0.0, s * 0.25]
    return a


def fortran(shape, values, dtype):
    """A multi-dim numpy array filled in column-major order (the RR wire order)."""
    return np.asarray(values, dtype=dtype).reshape(shape, order="F")


def everything(f, variant, depth=0):
    """A fully populated Everything struct. variant 0 = value A, 1 = value B."""
    v = variant
    s = f.struct("Everything")
    s.f_double = -1.7976931348623157e308 if v == 0 else 5e-324
    s.f_single = F32_MAX if v == 0 else F32_TINY_SUBNORMAL
    s.f_int8 = -128 if v == 0 else 127
    s.f_uint8 = 255 if v == 0 else 0
    s.f_int16 = -32768 if v == 0 else 32767
    s.f_uint16 = 65535 if v == 0 else 1
    s.f_int32 = -2147483648 if v == 0 else 2147483647
    s.f_uint32 = 4294967295 if v == 0 else 2
    s.f_int64 = -(2 ** 63) if v == 0 else 2 ** 63 - 1
    s.f_uint64 = 2 ** 64 - 1 if v == 0 else 3
    s.f_cdouble = complex(1.5, -2.25) if v == 0 else complex(-0.0, 1e300)
    s.f_csingle = complex(f32(0.5), f32(-0.25)) if v == 0 else complex(F32_MAX, F32_TINY_SUBNORMAL)
    s.f_bool = v == 0
    s.f_string = UTF8_TEXT if v == 0 else ""
    s.f_enum = COLOR["blue"] if v == 0 else COLOR["minus"]
    s.f_array = np.array([1.0, 2.0, 3.5 + v], dtype=np.float64)
    s.f_fixed = np.array([0.25, -0.25, 1e10 * (v + 1)], dtype=np.float64)
    s.f_bounded = np.array([1, -1, 300][: 3 - v], dtype=np.int16)
    s.f_md = fortran((2, 3), [1, 2, 3, 4, 5, 6 + v], np.float64)
    s.f_inner = inner(f, 10 + v)
    s.f_inner_null = None
    s.f_inner_list = [inner(f, 1), inner(f, 2, label="")] if v == 0 else []
    s.f_inner_by_int = {-5: inner(f, 5), 0: inner(f, 0), 2147483647: inner(f, 7)}
    s.f_inner_by_name = {"a": inner(f, 1), "\u00fc\u00f1\u00ee": inner(f, 2)} if v == 0 else {}
    s.f_strings = ["one", "", "\u4e09"] if v == 0 else None
    s.f_pod = test_pods(f, 1, seed=v)
    s.f_vec = vec3s(f, 1, seed=v)
    s.f_vecs = vec3s(f, 3 - v, seed=5)
    s.f_any = f.var(np.array([1, 2, 3], dtype=np.int32), "int32[]") if v == 0 else f.var("text", "string")
    s.f_any_null = None
    s.f_self = everything(f, v, depth + 1) if depth == 0 else None
    return s


# ---------------------------------------------------------------------------------------------------
# The varvalue catalogue: kind -> (value sent, value expected back after a round trip).
# Python turns scalars into 1-element arrays and typed containers into varvalue containers on receive
# (robdef.md §17.1), so a few kinds come back in a different but predictable form.

VARVALUE_KINDS = [
    "double[]", "single[]", "int8[]", "uint8[]", "int16[]", "uint16[]", "int32[]", "uint32[]",
    "int64[]", "uint64[]", "cdouble[]", "csingle[]", "bool[]", "empty double[]", "double scalar",
    "string", "empty string", "double[*]", "int32[*]", "struct", "struct everything", "pod[]",
    "pod[*]", "namedarray[]", "namedarray[*]", "varvalue{list}", "varvalue{int32}",
    "varvalue{string}", "string{list}", "double{int32}", "nested", "null",
]


def varvalue_catalog(f):
    V = f.var
    cat = {}

    def same(kind, value):
        cat[kind] = (value, value)

    same("double[]", V(np.array([0.0, -0.0, 1.5, np.inf, -np.inf, np.nan, 5e-324]), "double[]"))
    same("single[]", V(np.array([F32_MAX, -1.5, F32_TINY_SUBNORMAL], dtype=np.float32), "single[]"))
    same("int8[]", V(np.array([-128, 0, 127], dtype=np.int8), "int8[]"))
    same("uint8[]", V(np.array([0, 1, 255], dtype=np.uint8), "uint8[]"))
    same("int16[]", V(np.array([-32768, 32767], dtype=np.int16), "int16[]"))
    same("uint16[]", V(np.array([0, 65535], dtype=np.uint16), "uint16[]"))
    same("int32[]", V(np.array([-2147483648, 2147483647], dtype=np.int32), "int32[]"))
    same("uint32[]", V(np.array([0, 4294967295], dtype=np.uint32), "uint32[]"))
    same("int64[]", V(np.array([-(2 ** 63), 2 ** 63 - 1], dtype=np.int64), "int64[]"))
    same("uint64[]", V(np.array([0, 2 ** 64 - 1], dtype=np.uint64), "uint64[]"))
    same("cdouble[]", V(np.array([1 + 2j, -0.5 - 0.25j], dtype=np.complex128), "cdouble[]"))
    same("csingle[]", V(np.array([1 + 2j, -0.5 - 0.25j], dtype=np.complex64), "csingle[]"))
    same("bool[]", V(np.array([True, False, True]), "bool[]"))
    same("empty double[]", V(np.zeros((0,), dtype=np.float64), "double[]"))
    cat["double scalar"] = (V(3.25, "double"), V(np.array([3.25]), "double[]"))
    same("string", V(UTF8_TEXT, "string"))
    same("empty string", V("", "string"))
    same("double[*]", V(fortran((2, 3), [1, 2, 3, 4, 5, 6], np.float64), "double[*]"))
    same("int32[*]", V(fortran((2, 2, 2), range(8), np.int32), "int32[*]"))
    same("struct", V(inner(f, 3), qn("Inner")))
    same("struct everything", V(everything(f, 0), qn("Everything")))
    same("pod[]", V(test_pods(f, 2, seed=3), qn("TestPod[]")))
    same("pod[*]", V(test_pods(f, 6, seed=1).reshape((2, 3), order="F"), qn("TestPod[*]")))
    same("namedarray[]", V(vec3s(f, 2), qn("Vec3[]")))
    same("namedarray[*]", V(vec3s(f, 4).reshape((2, 2), order="F"), qn("Vec3[*]")))
    same("varvalue{list}", V([V("a", "string"), V(np.array([1], dtype=np.int32), "int32[]"), None],
                             "varvalue{list}"))
    same("varvalue{int32}", V({-1: V("minus one", "string"), 2147483647: V(np.array([2.0]), "double[]")},
                              "varvalue{int32}"))
    same("varvalue{string}", V({"k": V("v", "string"), "\u00fc": V(np.array([7], dtype=np.uint8), "uint8[]")},
                               "varvalue{string}"))
    cat["string{list}"] = (V(["x", "\u00ff"], "string{list}"),
                           V([V("x", "string"), V("\u00ff", "string")], "varvalue{list}"))
    cat["double{int32}"] = (V({3: 1.5, -4: 2.5}, "double{int32}"),
                            V({3: V(np.array([1.5]), "double[]"), -4: V(np.array([2.5]), "double[]")},
                              "varvalue{int32}"))
    same("nested", V({"list": V([V({"deep": V(inner(f, 9), qn("Inner"))}, "varvalue{string}")],
                                "varvalue{list}")}, "varvalue{string}"))
    cat["null"] = (None, None)
    assert list(cat) == VARVALUE_KINDS
    return cat


# ---------------------------------------------------------------------------------------------------
# Property values: name -> (A, B)


def property_values(f):
    V = f.var
    P = {}
    # primitives: the type's extremes
    P["p_double"] = (-1.7976931348623157e308, 5e-324)
    P["p_single"] = (F32_MAX, -F32_TINY_SUBNORMAL)
    P["p_int8"] = (-128, 127)
    P["p_uint8"] = (255, 0)
    P["p_int16"] = (-32768, 32767)
    P["p_uint16"] = (65535, 0)
    P["p_int32"] = (-2147483648, 2147483647)
    P["p_uint32"] = (4294967295, 0)
    P["p_int64"] = (-(2 ** 63), 2 ** 63 - 1)
    P["p_uint64"] = (2 ** 64 - 1, 0)
    P["p_cdouble"] = (complex(1.5, -2.25), complex(-0.0, 1e300))
    P["p_csingle"] = (complex(f32(0.5), f32(-0.25)), complex(F32_MAX, -F32_TINY_SUBNORMAL))
    P["p_bool"] = (True, False)
    P["p_string"] = (UTF8_TEXT, "")
    P["p_enum"] = (COLOR["blue"], COLOR["minus"])

    # numeric arrays
    P["a_double"] = (np.array([0.0, -0.0, 1.5, np.inf, -np.inf, np.nan, 5e-324, 1.7976931348623157e308]),
                     np.array([2.5]))
    P["a_single"] = (np.array([F32_MAX, -1.5, F32_TINY_SUBNORMAL, np.nan], dtype=np.float32),
                     np.array([1.0, 2.0], dtype=np.float32))
    P["a_int8"] = (np.array([-128, -1, 0, 1, 127], dtype=np.int8), np.array([5], dtype=np.int8))
    P["a_uint8"] = (np.arange(256, dtype=np.uint8), np.array([255, 0], dtype=np.uint8))
    P["a_int16"] = (np.array([-32768, 0, 32767], dtype=np.int16), np.array([-2], dtype=np.int16))
    P["a_uint16"] = (np.array([0, 1, 65535], dtype=np.uint16), np.array([7], dtype=np.uint16))
    P["a_int32"] = (np.array([-2147483648, 0, 2147483647], dtype=np.int32), np.array([9, 8], dtype=np.int32))
    P["a_uint32"] = (np.array([0, 4294967295], dtype=np.uint32), np.array([1], dtype=np.uint32))
    P["a_int64"] = (np.array([-(2 ** 63), -1, 2 ** 63 - 1], dtype=np.int64), np.array([0], dtype=np.int64))
    P["a_uint64"] = (np.array([0, 2 ** 64 - 1, 2 ** 63], dtype=np.uint64), np.array([42], dtype=np.uint64))
    P["a_cdouble"] = (np.array([1 + 2j, complex(-0.0, np.inf)], dtype=np.complex128),
                      np.array([0j], dtype=np.complex128))
    P["a_csingle"] = (np.array([1 - 2j, 0.5 + 0.25j], dtype=np.complex64), np.array([3j], dtype=np.complex64))
    P["a_bool"] = (np.array([True, False, False, True]), np.array([False]))
    P["a_fixed"] = (np.array([1.0, 2.0, 3.0]), np.array([-1.0, -2.0, -3.0]))
    P["a_bounded"] = (np.array([1, 2, 3, 4], dtype=np.int16), np.array([], dtype=np.int16))
    P["a_empty"] = (np.array([], dtype=np.uint8), np.array([1, 2, 3], dtype=np.uint8))

    # multi-dim numeric arrays (column-major on the wire)
    P["m_double"] = (fortran((2, 3), [1, 2, 3, 4, 5, 6], np.float64), fortran((1, 1), [9.5], np.float64))
    P["m_fixed"] = (fortran((2, 3), [-1, 2, -3, 4, -5, 6], np.int32), fortran((2, 3), range(6), np.int32))
    P["m_3d"] = (fortran((2, 3, 4), range(24), np.uint8), fortran((1, 2, 1), [7, 8], np.uint8))
    P["m_complex"] = (fortran((2, 2), [1j, 2, -3j, 4 + 4j], np.complex128), fortran((1, 3), [0, 1, 2], np.complex128))
    P["m_bool"] = (fortran((3, 2), [True, False, True, True, False, False], np.bool_),
                   fortran((1, 1), [True], np.bool_))

    # structs
    P["s_inner"] = (inner(f, 1), inner(f, -2, label="\u00e9t\u00e9", values=[]))
    P["s_everything"] = (everything(f, 0), everything(f, 1))
    P["s_null"] = (None, inner(f, 99))

    # pods
    P["pod_scalar"] = (test_pods(f, 1, seed=0), test_pods(f, 1, seed=4))
    P["pod_array"] = (test_pods(f, 3, seed=0), test_pods(f, 0))
    P["pod_fixed"] = (test_pods(f, 2, seed=10), test_pods(f, 2, seed=20))
    P["pod_md"] = (test_pods(f, 6).reshape((3, 2), order="F"), test_pods(f, 1, seed=2).reshape((1, 1), order="F"))

    # namedarrays
    P["na_scalar"] = (vec3s(f, 1), vec3s(f, 1, seed=3))
    P["na_array"] = (vec3s(f, 4), vec3s(f, 0))
    P["na_nested"] = (poses(f, 2), poses(f, 1, seed=9))
    P["na_md"] = (vec3s(f, 6).reshape((2, 3), order="F"), vec3s(f, 2).reshape((2, 1), order="F"))

    # containers
    P["map_int"] = ({-2147483648: 1.0, -1: -0.0, 0: np.nan, 2147483647: 5e-324}, {})
    P["map_str"] = ({"": "empty key", "key": "value", "\u00fc\u00f1\u00ee \U0001F916": UTF8_TEXT}, {"x": ""})
    P["map_struct"] = ({1: inner(f, 1), -7: inner(f, -7)}, {0: inner(f, 0)})
    P["map_pod"] = ({"first": test_pods(f, 1, seed=1), "second": test_pods(f, 1, seed=2)}, {})
    P["list_str"] = (["a", "", UTF8_TEXT], ["only"])
    P["list_struct"] = ([inner(f, 1), inner(f, 2), inner(f, 3)], [])
    P["list_arrays"] = ([np.array([1.0]), np.array([]), np.array([2.0, 3.0])], [np.array([4.0])])
    P["list_enum"] = ([COLOR["red"], COLOR["green"], COLOR["blue"], COLOR["minus"]], [COLOR["green"]])
    P["list_na"] = ([vec3s(f, 1, seed=1), vec3s(f, 1, seed=2)], [vec3s(f, 1, seed=8)])
    P["map_null"] = (None, {5: 5.5})
    P["list_empty"] = ([], ["now", "full"])

    # varvalues
    cat = varvalue_catalog(f)
    P["v_any"] = (cat["struct"][1], cat["int32[*]"][1])
    P["v_map"] = ({k: cat[k][1] for k in VARVALUE_KINDS}, {})
    P["v_list"] = ([cat["string"][1], cat["pod[]"][1], None, cat["varvalue{int32}"][1]], [])
    P["v_null"] = (None, cat["string"][1])

    # modifiers (nolock behaves like a normal property)
    P["nolock_value"] = (11, 12)
    return P


# Values of the other members
BASE_NAME = "interop root"
RO_VALUE = 17
CHILD_INT_KEYS = [-1, 0, 7]
CHILD_STR_KEYS = ["alpha", "with space_and-dash"]
CALLBACK_LABEL = "\u03bb-label"
STATE_PERIOD_S = 0.2
MEM_DOUBLE_LEN = 100
MEM_MD_SHAPE = (4, 5)
MEM_POD_LEN = 4
MEM_NA_LEN = 5
MEM_RO_LEN = 16


def child_name(key):
    return "child[%s]" % (key,)


def event_text(seq):
    return "event %d \u2713" % seq


def event_data(f, seq):
    return inner(f, seq, label="event", values=[seq * 1.5])


def stream_packet(i):
    return np.array([float(i), i * 0.5])


def state_value(f, seq, label):
    return inner(f, seq, label=label, values=[seq * 0.25])


def mem_double_initial():
    return np.arange(MEM_DOUBLE_LEN, dtype=np.float64) * 0.5


def mem_md_initial():
    return fortran(MEM_MD_SHAPE, range(MEM_MD_SHAPE[0] * MEM_MD_SHAPE[1]), np.int32) - 10


def mem_pod_initial(f):
    return test_pods(f, MEM_POD_LEN, seed=30)


def mem_pod_md_initial(f):
    return test_pods(f, 6, seed=40).reshape((2, 3), order="F")


def mem_na_initial(f):
    return vec3s(f, MEM_NA_LEN, seed=50)


def mem_na_md_initial(f):
    return vec3s(f, 6, seed=60).reshape((3, 2), order="F")


def mem_ro_initial():
    return np.arange(MEM_RO_LEN, dtype=np.uint8) * 3


def mix_result(f, a, b, c, d, e, f_, g, h):
    """What mix(a..h) returns: Everything(A) with the parameters written into some fields."""
    s = everything(f, 0)
    s.f_double = a
    s.f_string = b
    s.f_inner = c
    s.f_pod = d
    s.f_vec = e
    s.f_any = f_
    s.f_enum = g
    s.f_strings = [str(x) for x in h]
    return s


# ---------------------------------------------------------------------------------------------------
# Comparison


def _float_bits(x):
    return struct.pack("<d", x)


def _is_struct(x):
    return hasattr(type(x), "__slots__") and type(x).__name__.startswith(SERVICE.replace(".", "__") + "__")


def _is_varvalue(x):
    return type(x).__name__ == "RobotRaconteurVarValue"


def deep_equal(a, b, path="value"):
    """None when a equals b exactly, else a one-line description of the first difference."""
    if isinstance(a, np.generic) and not isinstance(a, np.void):
        a = a.item()
    if isinstance(b, np.generic) and not isinstance(b, np.void):
        b = b.item()
    if a is None or b is None:
        if a is None and b is None:
            return None
        return "%s: %r != %r" % (path, a, b)
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        if not (isinstance(a, np.ndarray) and isinstance(b, np.ndarray)):
            return "%s: %s is not %s" % (path, type(a).__name__, type(b).__name__)
        if a.dtype != b.dtype:
            return "%s: dtype %s != %s" % (path, a.dtype, b.dtype)
        if a.shape != b.shape:
            return "%s: shape %s != %s" % (path, a.shape, b.shape)
        if np.ascontiguousarray(a).tobytes() != np.ascontiguousarray(b).tobytes():
            return "%s: array contents differ: %r != %r" % (path, a, b)
        return None
    if _is_varvalue(a) or _is_varvalue(b):
        if not (_is_varvalue(a) and _is_varvalue(b)):
            return "%s: %s is not %s" % (path, type(a).__name__, type(b).__name__)
        if a.datatype != b.datatype:
            return "%s: varvalue type %r != %r" % (path, a.datatype, b.datatype)
        return deep_equal(a.data, b.data, path + "<" + a.datatype + ">")
    if _is_struct(a) or _is_struct(b):
        if type(a).__name__ != type(b).__name__:
            return "%s: struct %s != %s" % (path, type(a).__name__, type(b).__name__)
        for field in type(a).__slots__:
            d = deep_equal(getattr(a, field), getattr(b, field), path + "." + field)
            if d:
                return d
        return None
    if isinstance(a, dict) or isinstance(b, dict):
        if not (isinstance(a, dict) and isinstance(b, dict)):
            return "%s: %s is not %s" % (path, type(a).__name__, type(b).__name__)
        if set(a) != set(b):
            return "%s: keys %r != %r" % (path, sorted(a, key=repr), sorted(b, key=repr))
        for k in a:
            d = deep_equal(a[k], b[k], "%s[%r]" % (path, k))
            if d:
                return d
        return None
    if isinstance(a, (list, tuple)) or isinstance(b, (list, tuple)):
        if not (isinstance(a, (list, tuple)) and isinstance(b, (list, tuple))):
            return "%s: %s is not %s" % (path, type(a).__name__, type(b).__name__)
        if len(a) != len(b):
            return "%s: length %d != %d" % (path, len(a), len(b))
        for i, (x, y) in enumerate(zip(a, b)):
            d = deep_equal(x, y, "%s[%d]" % (path, i))
            if d:
                return d
        return None
    if isinstance(a, (bool, np.bool_)) or isinstance(b, (bool, np.bool_)):
        if isinstance(a, (bool, np.bool_)) and isinstance(b, (bool, np.bool_)) and bool(a) == bool(b):
            return None
        return "%s: %r != %r" % (path, a, b)
    if isinstance(a, str) or isinstance(b, str):
        if isinstance(a, str) and isinstance(b, str) and a == b:
            return None
        return "%s: %r != %r" % (path, a, b)
    if isinstance(a, complex) or isinstance(b, complex):
        if not (isinstance(a, complex) and isinstance(b, complex)):
            return "%s: %r is not %r" % (path, a, b)
        if _float_bits(a.real) == _float_bits(b.real) and _float_bits(a.imag) == _float_bits(b.imag):
            return None
        return "%s: %r != %r" % (path, a, b)
    if isinstance(a, float) or isinstance(b, float):
        if not (isinstance(a, float) and isinstance(b, float)):
            return "%s: %r (%s) is not %r (%s)" % (path, a, type(a).__name__, b, type(b).__name__)
        if _float_bits(a) == _float_bits(b) or (math.isnan(a) and math.isnan(b)):
            return None
        return "%s: %r != %r" % (path, a, b)
    if isinstance(a, int) and isinstance(b, int):
        return None if a == b else "%s: %r != %r" % (path, a, b)
    return "%s: cannot compare %r (%s) with %r (%s)" % (path, a, type(a).__name__, b, type(b).__name__)

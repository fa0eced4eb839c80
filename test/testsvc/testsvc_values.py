"""The values rr-test-service serves and expects, computed independently of it, in Python.

- Lfsr: the official test suite's sequence generator (test/lfsr of robotraconteur/robotraconteur),
  written from its description, as test/testsvc/lfsr.cpp (docs there).
- Types: the test definitions, parsed by the official Python package (RobotRaconteur.ServiceDefinition),
  with named types resolved.
- lfsr_json(type, gen): the value drawn by the rules of test/testsvc/value_fill.hpp, as JSON in the
  project's JSON mapping (docs/json-mapping.md), the form every comparison here uses.
- Ts3: the TestService3 recipes (test/testsvc/sequence_gen.hpp), as JSON.
- to_json(value, type): a value the official client received, in that JSON form.
- from_json(json, type, obj): the official client's Python value for a JSON value, to send.

NaN is "NaN" in the JSON form, so NaN compares equal to NaN whatever its payload bits.
"""

import math
import struct

import numpy as np
import RobotRaconteur as RR

SEED = 55  # TestValues::kSeed

# --------------------------------------------------------------------------------------------------
# LFSR


def _step(s):
    bit = (s ^ (s >> 1) ^ (s >> 21) ^ (s >> 31)) & 1
    return ((s >> 1) | (bit << 31)) & 0xFFFFFFFF


def init_key(seed, key):
    s = seed & 0xFFFFFFFF
    for _ in range(128):
        s = _step(s)
    h = _step(s)
    for c in key.encode("ascii"):
        h = (h + c) & 0xFFFFFFFF
        h = (h + (h << 10)) & 0xFFFFFFFF
        h ^= h >> 6
    h = (h + (h << 3)) & 0xFFFFFFFF
    h ^= h >> 11
    h = (h + (h << 15)) & 0xFFFFFFFF
    for _ in range(128):
        h = _step(h)
    return _step(h)


class Lfsr:
    PRINTABLE = "".join(chr(c) for c in range(32, 127))

    def __init__(self, seed, key=None, state=None):
        self.state = state if state is not None else init_key(seed, key)

    def _next(self):
        self.state = _step(self.state)
        return self.state

    def _cast32(self, fmt):
        return struct.unpack("<" + fmt, struct.pack("<I", self._next())[: struct.calcsize(fmt)])[0]

    def next_uint64(self):
        high = self._next()
        low = self._next()
        return (high << 32) | low

    def next_int8(self): return self._cast32("b")
    def next_uint8(self): return self._cast32("B")
    def next_int16(self): return self._cast32("h")
    def next_uint16(self): return self._cast32("H")
    def next_int32(self): return self._cast32("i")
    def next_uint32(self): return self._next()
    def next_int64(self): return struct.unpack("<q", struct.pack("<Q", self.next_uint64()))[0]
    def next_float(self): return struct.unpack("<f", struct.pack("<I", self._next()))[0]
    def next_double(self): return struct.unpack("<d", struct.pack("<Q", self.next_uint64()))[0]
    def next_bool(self): return (self._next() & 1) != 0

    def next_cfloat(self):
        re = self.next_float()
        return complex(re, self.next_float())

    def next_cdouble(self):
        re = self.next_double()
        return complex(re, self.next_double())

    def next_char(self): return self.PRINTABLE[self._next() % 95]

    def next_len(self, max_len):
        s = self._next()
        return s % max_len if max_len < 32 else 8 + s % (max_len - 8)

    def next_dist(self, lo, hi): return self._next() % (hi - lo + 1) + lo
    def next_string(self, n): return "".join(self.next_char() for _ in range(n))
    def next_string_var_len(self, max_len): return self.next_string(self.next_len(max_len))


# --------------------------------------------------------------------------------------------------
# Types

D = RR  # DataTypes_* constants
NUMERIC = {D.DataTypes_double_t: "double", D.DataTypes_single_t: "single", D.DataTypes_int8_t: "int8",
           D.DataTypes_uint8_t: "uint8", D.DataTypes_int16_t: "int16", D.DataTypes_uint16_t: "uint16",
           D.DataTypes_int32_t: "int32", D.DataTypes_uint32_t: "uint32", D.DataTypes_int64_t: "int64",
           D.DataTypes_uint64_t: "uint64", D.DataTypes_cdouble_t: "cdouble", D.DataTypes_csingle_t: "csingle",
           D.DataTypes_bool_t: "bool"}
NP_DTYPE = {"double": np.float64, "single": np.float32, "int8": np.int8, "uint8": np.uint8, "int16": np.int16,
            "uint16": np.uint16, "int32": np.int32, "uint32": np.uint32, "int64": np.int64, "uint64": np.uint64,
            "cdouble": np.complex128, "csingle": np.complex64, "bool": np.bool_}
NONE, ARRAY, MULTI = 0, 1, 2
C_NONE, C_LIST, C_MAP_INT, C_MAP_STR, C_GEN = 0, 1, 2, 3, 4


class T:
    """A resolved type: base (numeric keyword, 'string', 'varvalue', or a named kind), array shape, container."""

    def __init__(self, base, array=NONE, length=(), varlen=False, container=C_NONE, named=None, kind=None):
        self.base, self.array, self.length, self.varlen = base, array, list(length), varlen
        self.container, self.named, self.kind = container, named, kind

    def item(self):
        return T(self.base, self.array, self.length, self.varlen, C_NONE, self.named, self.kind)

    def scalar(self):
        return T(self.base, NONE, (), False, C_NONE, self.named, self.kind)

    def __repr__(self):
        return "T(%s%s %s %s %s)" % (self.base, self.named or "", self.array, self.length, self.container)


class Types:
    """The definitions (texts) parsed by the official package; entries and enums by qualified name."""

    def __init__(self, texts):
        self.defs = {}
        for text in texts:
            d = RR.ServiceDefinition()
            d.FromString(text)
            self.defs[d.Name] = d
        self.entries = {}  # qualified -> (kind, service, [(name, T)], members lines)
        self.enums = {}    # qualified -> [(name, value)]
        self.objects = {}  # qualified -> [member lines]
        for svc, d in self.defs.items():
            for e in d.Enums:
                self.enums[svc + "." + e.Name] = [(v.Name, v.Value) for v in e.Values]
        for svc, d in self.defs.items():
            for kind, entries in (("struct", d.Structures), ("pod", d.Pods), ("namedarray", d.NamedArrays)):
                for e in entries:
                    self.entries[svc + "." + e.Name] = (kind, svc, [m.ToString() for m in e.Members])
            for e in d.Objects:
                self.objects[svc + "." + e.Name] = (svc, [m.ToString() for m in e.Members])

    def qualify(self, name, svc):
        if "." in name:
            return name
        d = self.defs[svc]
        own = {e.Name for e in list(d.Structures) + list(d.Pods) + list(d.NamedArrays) + list(d.Objects)}
        own |= {e.Name for e in d.Enums}
        if name in own:
            return svc + "." + name
        for u in d.Using:
            if u.UnqualifiedName == name:
                return u.QualifiedName
        raise KeyError("cannot resolve %s in %s" % (name, svc))

    def parse(self, text, svc):
        """A type token (`double[6-]`, `testpod1[*]{list}`, a qualified name) of service `svc`."""
        td = RR.TypeDefinition()
        td.FromString(text + " value")
        base = td.Type
        named = kind = None
        if base in NUMERIC:
            b = NUMERIC[base]
        elif base == D.DataTypes_string_t:
            b = "string"
        elif base == D.DataTypes_varvalue_t:
            b = "varvalue"
        elif base == D.DataTypes_namedtype_t:
            named = self.qualify(td.TypeString, svc)
            kind = "enum" if named in self.enums else self.entries[named][0]
            b = kind
        else:
            raise ValueError("unsupported type " + text)
        return T(b, td.ArrayType, list(td.ArrayLength), td.ArrayVarLength, td.ContainerType, named, kind)

    def fields(self, qualified):
        kind, svc, lines = self.entries[qualified]
        out = []
        for line in lines:
            _, rest = line.split(" ", 1)
            typ, name = rest.split(" ")[:2]
            out.append((name, self.parse(typ, svc)))
        return out

    def members(self, qualified):
        """Object members: (kind, name, type or None, [(param name, T)], modifiers text)."""
        svc, lines = self.objects[qualified]
        out = []
        for line in lines:
            kind, rest = line.split(" ", 1)
            mods = ""
            if rest.endswith("]") and " [" in rest:
                rest, mods = rest[: rest.rindex(" [")], rest[rest.rindex(" [") + 2: -1]
            if kind in ("function", "callback", "event"):
                head, params = rest.split("(", 1)
                params = params.rstrip(")")
                ps = []
                for p in [p.strip() for p in params.split(",") if p.strip()]:
                    pt, pn = p.rsplit(" ", 1)
                    ps.append((pn, self.parse(pt, svc)))
                if kind == "event":
                    out.append((kind, head.strip(), None, ps, mods))
                else:
                    rt, name = head.strip().split(" ")
                    out.append((kind, name, None if rt == "void" else self.parse(rt, svc), ps, mods))
            elif kind == "objref":
                typ, name = rest.split(" ")
                out.append((kind, name, None, [], mods))
            else:
                typ, name = rest.split(" ")
                out.append((kind, name, self.parse(typ, svc), [], mods))
        return out

    def namedarray_layout(self, qualified):
        """(element keyword, numbers per item)."""
        elem, n = None, 0
        for _, t in self.fields(qualified):
            count = t.length[0] if t.array == ARRAY else 1
            if t.kind == "namedarray":
                e, k = self.namedarray_layout(t.named)
                elem, n = e, n + k * count
            else:
                elem, n = t.base, n + count
        return elem, n


# --------------------------------------------------------------------------------------------------
# JSON form of numbers


def num(x, base):
    if base in ("double", "single"):
        x = float(x)
        if math.isnan(x):
            return "NaN"
        if math.isinf(x):
            return "Infinity" if x > 0 else "-Infinity"
        return x
    if base in ("cdouble", "csingle"):
        x = complex(x)
        part = "double" if base == "cdouble" else "single"
        return {"re": num(x.real, part), "im": num(x.imag, part)}
    if base == "bool":
        return bool(x)
    return int(x)


def unnum(j, base):
    if base in ("double", "single"):
        return float("nan") if j == "NaN" else float("inf") if j == "Infinity" else float("-inf") if j == "-Infinity" else float(j)
    if base in ("cdouble", "csingle"):
        part = "double" if base == "cdouble" else "single"
        return complex(unnum(j["re"], part), unnum(j["im"], part))
    if base == "bool":
        return bool(j)
    return int(j)


_DRAW = {"double": "next_double", "single": "next_float", "int8": "next_int8", "uint8": "next_uint8",
         "int16": "next_int16", "uint16": "next_uint16", "int32": "next_int32", "uint32": "next_uint32",
         "int64": "next_int64", "uint64": "next_uint64", "cdouble": "next_cdouble", "csingle": "next_cfloat",
         "bool": "next_bool"}


def draw(g, base):
    return num(getattr(g, _DRAW[base])(), base)


# --------------------------------------------------------------------------------------------------
# LFSR values (value_fill.hpp), as JSON

MAX_VAR = 16
MAX_DEPTH = 4


def _shape(t, g):
    """(count, dims or None)."""
    if t.array == ARRAY:
        n = t.length[0] if t.length else 0
        if n == 0:
            return g.next_len(MAX_VAR), None
        if not t.varlen:
            return n, None
        return g.next_len(n + 1), None
    if t.array == MULTI:
        dims = list(t.length)
        if not dims or dims == [0]:
            dims = [g.next_dist(1, 4) for _ in range(g.next_dist(1, 3))]
        c = 1
        for d in dims:
            c *= d
        return c, dims
    return 1, None


def _shaped(t, items, dims):
    if t.array == MULTI:
        return {"dims": dims, "array": items}
    if t.array == ARRAY:
        return items
    return items[0]


def lfsr_json(types, t, g, depth=0):
    if t.container in (C_LIST, C_MAP_INT, C_MAP_STR):
        n = g.next_dist(1, 3)
        item = t.item()
        if t.container == C_LIST:
            return [lfsr_json(types, item, g, depth) for _ in range(n)]
        out = {}
        for _ in range(n):
            while True:
                k = str(g.next_dist(0, 999)) if t.container == C_MAP_INT else g.next_string(g.next_dist(1, 8))
                if k not in out:
                    break
            out[k] = lfsr_json(types, item, g, depth)
        return out
    if t.base == "varvalue":
        kind = g.next_dist(0, 3)
        if kind == 0:
            return {"type": "double[]", "value": [draw(g, "double") for _ in range(g.next_len(MAX_VAR))]}
        if kind == 1:
            return {"type": "int32[]", "value": [draw(g, "int32") for _ in range(g.next_len(MAX_VAR))]}
        if kind == 2:
            return {"type": "string", "value": g.next_string_var_len(MAX_VAR)}
        dims = [g.next_dist(1, 4) for _ in range(g.next_dist(1, 3))]
        c = int(np.prod(dims))
        return {"type": "double[*]", "value": {"dims": dims, "array": [draw(g, "double") for _ in range(c)]}}
    if t.base == "string":
        return g.next_string_var_len(MAX_VAR)
    if t.base in _DRAW:
        c, dims = _shape(t, g)
        return _shaped(t, [draw(g, t.base) for _ in range(c)], dims)
    if t.kind == "enum":
        values = types.enums[t.named]
        i = g.next_dist(0, len(values) - 1) if len(values) > 1 else 0
        return values[i][1]
    if t.kind == "struct":
        if depth >= MAX_DEPTH:
            return None
        return {name: lfsr_json(types, ft, g, depth + 1) for name, ft in types.fields(t.named)}
    if t.kind == "pod":
        c, dims = _shape(t, g)
        items = [{name: lfsr_json(types, ft, g, depth + 1) for name, ft in types.fields(t.named)} for _ in range(c)]
        return _shaped(t, items, dims)
    if t.kind == "namedarray":
        c, dims = _shape(t, g)
        elem, k = types.namedarray_layout(t.named)
        flat = [draw(g, elem) for _ in range(c * k)]
        items = [namedarray_item_json(types, t.named, flat[i * k:(i + 1) * k]) for i in range(c)]
        return _shaped(t, items, dims)
    raise ValueError("no value of %r" % t)


def namedarray_item_json(types, qualified, flat):
    """One namedarray item (flat numbers) as its field object."""
    out, i = {}, 0
    for name, ft in types.fields(qualified):
        count = ft.length[0] if ft.array == ARRAY else 1
        if ft.kind == "namedarray":
            _, k = types.namedarray_layout(ft.named)
            items = [namedarray_item_json(types, ft.named, flat[i + j * k: i + (j + 1) * k]) for j in range(count)]
            i += k * count
        else:
            items = flat[i:i + count]
            i += count
        out[name] = items if ft.array == ARRAY else items[0]
    return out


def namedarray_item_flat(types, qualified, obj):
    out = []
    for name, ft in types.fields(qualified):
        v = obj[name] if ft.array == ARRAY else [obj[name]]
        for x in v:
            out.extend(namedarray_item_flat(types, ft.named, x) if ft.kind == "namedarray" else [x])
    return out


# --------------------------------------------------------------------------------------------------
# The TestService3 recipes (sequence_gen.hpp), as JSON

TS3 = "com.robotraconteur.testing.TestService3"


class SequenceTables:
    def __init__(self, doubles, uint32s):
        self.doubles, self.uint32s = doubles, uint32s

    @staticmethod
    def lfsr(seed=SEED):
        d = Lfsr(seed, "sequence_doubles")
        doubles = [d.next_uint32() / 4294967296.0 for _ in range(7919)]
        u = Lfsr(seed, "sequence_uint32s")
        return SequenceTables(doubles, [u.next_uint32() for _ in range(7727)])


class SequenceGen:
    def __init__(self, tables, seed):
        self.t, self.counter, self.step = tables, seed % 7823, seed % 17 + 7

    def double(self):
        self.counter += self.step
        return self.t.doubles[self.counter % len(self.t.doubles)]

    def uint32(self):
        self.counter += self.step
        return self.t.uint32s[self.counter % len(self.t.uint32s)]

    def int8(self):
        self.counter += self.step
        return self.counter % 255 - 128


class Ts3:
    def __init__(self, types, tables):
        self.types, self.tables = types, tables

    def _transform_flat(self, seed):
        g = SequenceGen(self.tables, seed)
        return [g.double() for _ in range(7)]

    def transform(self, seed):
        return namedarray_item_json(self.types, TS3 + ".transform", self._transform_flat(seed))

    def vector3_of_transform(self, seed):
        return self.transform(seed)["translation"]

    def _transforms(self, g, n):
        return [self.transform(g.uint32()) for _ in range(n)]

    def transform_array(self, n, seed):
        return self._transforms(SequenceGen(self.tables, seed), n)

    def transform_multidim(self, m, n, seed):
        return {"dims": [m, n], "array": self._transforms(SequenceGen(self.tables, seed), m * n)}

    def testpod2(self, seed):
        g = SequenceGen(self.tables, seed)
        i1 = g.int8()
        i2 = [g.int8() for _ in range(15)]
        n = g.uint32() % 15
        return {"i1": i1, "i2": i2, "i3": [g.int8() for _ in range(n)]}

    def testpod1(self, seed):
        g = SequenceGen(self.tables, seed)
        o = {"d1": g.double(), "d2": [g.double() for _ in range(6)]}
        n = g.uint32() % 6
        o["d3"] = [g.double() for _ in range(n)]
        o["d4"] = {"dims": [3, 3], "array": [g.double() for _ in range(9)]}
        o["s1"] = self.testpod2(g.uint32())
        o["s2"] = [self.testpod2(g.uint32()) for _ in range(8)]
        n = g.uint32() % 9
        o["s3"] = [self.testpod2(g.uint32()) for _ in range(n)]
        o["s4"] = {"dims": [2, 4], "array": [self.testpod2(g.uint32()) for _ in range(8)]}
        o["t1"] = self.transform(g.uint32())
        o["t2"] = self._transforms(g, 4)
        n = g.uint32() % 15
        o["t3"] = self._transforms(g, n)
        o["t4"] = {"dims": [2, 4], "array": self._transforms(g, 8)}
        return o

    def testpod1_array(self, n, seed):
        g = SequenceGen(self.tables, seed)
        return [self.testpod1(g.uint32()) for _ in range(n)]

    def testpod1_multidim(self, m, n, seed):
        g = SequenceGen(self.tables, seed)
        return {"dims": [m, n], "array": [self.testpod1(g.uint32()) for _ in range(m * n)]}

    def teststruct3(self, seed):
        g = SequenceGen(self.tables, seed)
        u = g.uint32
        pod = TS3 + ".testpod1"
        tr = TS3 + ".transform"
        o = {"s1": self.testpod1(u())}
        s = u()
        o["s2"] = self.testpod1_array(s % 17, s)
        o["s3"] = self.testpod1_array(11, u())
        s = u()
        o["s4"] = self.testpod1_array(s % 16, s)
        o["s5"] = self.testpod1_multidim(3, 3, u())
        s = u()
        o["s6"] = self.testpod1_multidim(s % 6, s % 3, s)
        o["s7"] = [self.testpod1(u())]
        o["s8"] = [self.testpod1_array(2, u()), self.testpod1_array(4, u())]
        o["s9"] = [self.testpod1_multidim(2, 3, u()), self.testpod1_multidim(4, 5, u())]
        o["s10"] = {"type": pod + "[]", "value": [self.testpod1(u())]}
        o["s11"] = {"type": pod + "[]", "value": self.testpod1_array(3, u())}
        o["s12"] = {"type": pod + "[*]", "value": self.testpod1_multidim(2, 2, u())}
        o["s13"] = {"type": "varvalue{list}", "value": [{"type": pod + "[]", "value": [self.testpod1(u())]}]}
        a = self.testpod1_array(3, u())
        o["s14"] = {"type": "varvalue{list}", "value": [{"type": pod + "[]", "value": a},
                                                        {"type": pod + "[]", "value": self.testpod1_array(5, u())}]}
        a = self.testpod1_multidim(7, 2, u())
        o["s15"] = {"type": "varvalue{list}", "value": [{"type": pod + "[*]", "value": a},
                                                        {"type": pod + "[*]", "value": self.testpod1_multidim(5, 1, u())}]}
        o["t1"] = self.transform(u())
        o["t2"] = self.transform_array(4, u())
        o["t3"] = self.transform_multidim(2, 4, u())
        o["t4"] = {"type": tr + "[]", "value": self.transform_array(10, u())}
        o["t5"] = {"type": tr + "[*]", "value": self.transform_multidim(6, 5, u())}
        o["t6"] = [self.transform(u())]
        o["t7"] = [self.transform_array(4, u()), self.transform_array(4, u())]
        o["t8"] = [self.transform_multidim(2, 4, u()), self.transform_multidim(2, 4, u())]
        o["t9"] = {"type": "varvalue{list}", "value": [{"type": tr + "[]", "value": [self.transform(u())]}]}
        a = self.transform_array(3, u())
        o["t10"] = {"type": "varvalue{list}", "value": [{"type": tr + "[]", "value": a},
                                                        {"type": tr + "[]", "value": self.transform_array(5, u())}]}
        a = self.transform_multidim(7, 2, u())
        o["t11"] = {"type": "varvalue{list}", "value": [{"type": tr + "[*]", "value": a},
                                                        {"type": tr + "[*]", "value": self.transform_multidim(5, 1, u())}]}
        return o


# --------------------------------------------------------------------------------------------------
# Official Python client values <-> JSON


def _var_type(types, s):
    return types.parse(s, "")


def to_json(types, v, t):
    """A value as the official client gives it, for type `t`, in the JSON form."""
    if t.container in (C_LIST, C_MAP_INT, C_MAP_STR):
        if v is None:
            return None
        item = t.item()
        if t.container == C_LIST:
            return [to_json(types, x, item) for x in v]
        return {str(k): to_json(types, x, item) for k, x in v.items()}
    if t.base == "varvalue":
        if v is None:
            return None
        vt = _var_type(types, v.datatype)
        return {"type": v.datatype, "value": to_json(types, v.data, vt)}
    if t.base == "string":
        return v
    if t.base in NUMERIC.values():
        # with the dtype: a list of large uint64 would become float64 (and lose digits) otherwise
        if t.array == MULTI:
            a = np.asarray(v, dtype=NP_DTYPE[t.base])
            return {"dims": list(a.shape), "array": [num(x, t.base) for x in a.flatten(order="F")]}
        if t.array == ARRAY:
            return [num(x, t.base) for x in np.atleast_1d(np.asarray(v, dtype=NP_DTYPE[t.base])).flatten()]
        return num(np.asarray(v).flatten()[0] if isinstance(v, np.ndarray) else v, t.base)
    if t.kind == "enum":
        return int(v)
    if t.kind == "struct":
        if v is None:
            return None
        return {name: to_json(types, getattr(v, name), ft) for name, ft in types.fields(t.named)}
    if t.kind in ("pod", "namedarray"):
        a = np.asarray(v)
        if t.kind == "pod":
            def item(x):
                return pod_item_json(types, t.named, x)
        else:
            elem, _ = types.namedarray_layout(t.named)

            def item(x):
                flat = np.atleast_1d(np.asarray(x)).view(NP_DTYPE[elem]).flatten()
                return namedarray_item_json(types, t.named, [num(y, elem) for y in flat])
        if t.array == MULTI:
            return {"dims": list(a.shape), "array": [item(x) for x in a.flatten(order="F")]}
        if t.array == ARRAY:
            return [item(x) for x in np.atleast_1d(a).flatten()]
        return item(np.atleast_1d(a).flatten()[0])
    raise ValueError("no JSON of %r" % t)


def pod_item_json(types, qualified, x):
    out = {}
    for name, ft in types.fields(qualified):
        f = x[name]
        if ft.array == ARRAY and ft.varlen:
            f = f["array"][: int(f["len"])]
        if ft.kind == "pod":
            sub = T("pod", ft.array, ft.length, False, C_NONE, ft.named, "pod")
            out[name] = to_json(types, np.asarray(f), sub)
        elif ft.kind == "namedarray":
            sub = T("namedarray", ft.array, ft.length, False, C_NONE, ft.named, "namedarray")
            out[name] = to_json(types, np.asarray(f), sub)
        else:
            out[name] = to_json(types, f, T(ft.base, ft.array, ft.length, False))
    return out


def _na_tuple(types, qualified, obj):
    out = []
    for name, ft in types.fields(qualified):
        v = obj[name]
        if ft.kind == "namedarray":
            out.append([_na_tuple(types, ft.named, x) for x in v] if ft.array == ARRAY else _na_tuple(types, ft.named, v))
        else:
            out.append([unnum(x, ft.base) for x in v] if ft.array == ARRAY else unnum(v, ft.base))
    return tuple(out)


def _pod_tuple(types, qualified, obj, dtype):
    out = []
    for name, ft in types.fields(qualified):
        v = obj[name]
        sub = dtype[name]
        if ft.array == MULTI:
            items = v["array"]
            if ft.kind == "pod":
                arr = np.zeros(len(items), dtype=sub.base)
                for i, x in enumerate(items):
                    arr[i] = _pod_tuple(types, ft.named, x, sub.base)
            elif ft.kind == "namedarray":
                arr = np.zeros(len(items), dtype=sub.base)
                for i, x in enumerate(items):
                    arr[i] = _na_tuple(types, ft.named, x)
            else:
                arr = np.array([unnum(x, ft.base) for x in items], dtype=NP_DTYPE[ft.base])
            out.append(arr.reshape(v["dims"], order="F"))
            continue
        seq = v if ft.array == ARRAY else [v]
        if ft.kind == "pod":
            conv = [_pod_tuple(types, ft.named, x, sub.base if ft.array == ARRAY and not ft.varlen else
                               (sub["array"].base if ft.varlen else sub)) for x in seq]
        elif ft.kind == "namedarray":
            conv = [_na_tuple(types, ft.named, x) for x in seq]
        else:
            conv = [unnum(x, ft.base) for x in seq]
        if ft.array == ARRAY and ft.varlen:
            arr = np.zeros(sub["array"].shape, dtype=sub["array"].base)
            for i, x in enumerate(conv):
                arr[i] = x
            out.append((len(conv), arr))
        elif ft.array == ARRAY:
            if ft.kind in ("pod", "namedarray"):
                arr = np.zeros(len(conv), dtype=sub.base)
                for i, x in enumerate(conv):
                    arr[i] = x
                out.append(arr)
            else:
                out.append(np.array(conv, dtype=NP_DTYPE[ft.base]))
        else:
            out.append(conv[0])
    return tuple(out)


def from_json(types, j, t, obj):
    """The official client's value for JSON `j` of type `t` (named types pulled through client object `obj`)."""
    RRN = RR.RobotRaconteurNode.s
    if t.container in (C_LIST, C_MAP_INT, C_MAP_STR):
        if j is None:
            return None
        item = t.item()
        if t.container == C_LIST:
            return [from_json(types, x, item, obj) for x in j]
        if t.container == C_MAP_INT:
            return {int(k): from_json(types, x, item, obj) for k, x in j.items()}
        return {k: from_json(types, x, item, obj) for k, x in j.items()}
    if t.base == "varvalue":
        if j is None:
            return None
        return RR.VarValue(from_json(types, j["value"], _var_type(types, j["type"]), obj), j["type"])
    if t.base == "string":
        return j
    if t.base in NUMERIC.values():
        dt = NP_DTYPE[t.base]
        if t.array == MULTI:
            return np.array([unnum(x, t.base) for x in j["array"]], dtype=dt).reshape(j["dims"], order="F")
        if t.array == ARRAY:
            return np.array([unnum(x, t.base) for x in j], dtype=dt)
        return dt(unnum(j, t.base)) if t.base in ("single", "csingle") else unnum(j, t.base)
    if t.kind == "enum":
        return int(j)
    if t.kind == "struct":
        if j is None:
            return None
        s = RRN.NewStructure(t.named, obj)
        for name, ft in types.fields(t.named):
            setattr(s, name, from_json(types, j[name], ft, obj))
        return s
    if t.kind in ("pod", "namedarray"):
        dtype = RRN.GetPodDType(t.named, obj) if t.kind == "pod" else RRN.GetNamedArrayDType(t.named, obj)
        items = j["array"] if t.array == MULTI else j if t.array == ARRAY else [j]
        a = np.zeros(len(items), dtype=dtype)
        for i, x in enumerate(items):
            a[i] = _pod_tuple(types, t.named, x, dtype) if t.kind == "pod" else _na_tuple(types, t.named, x)
        return a.reshape(j["dims"], order="F") if t.array == MULTI else a
    raise ValueError("no value of %r" % t)

#include "test/testsvc/sequence_gen.hpp"

#include "test/testsvc/lfsr.hpp"

namespace rr::testsvc {
namespace {

const std::string kTs3 = "com.robotraconteur.testing.TestService3";
const std::string kTransform = kTs3 + ".transform";
const std::string kVector3 = kTs3 + ".vector3";
const std::string kTestpod1 = kTs3 + ".testpod1";
const std::string kTestpod2 = kTs3 + ".testpod2";

template <class T, class Next>
Value numbers(std::size_t n, Next next) {
    std::vector<T> v(n);
    for (auto& x : v) x = next();
    return Value(NumericArray::adopt<T>(std::move(v)));
}

PodArray pod_array(const std::string& type, std::vector<std::string> names, std::vector<std::vector<Value>> items,
                   std::vector<std::uint32_t> dims = {}) {
    PodArray p(type, std::move(names));
    for (auto& item : items) (void)p.push_back(std::move(item));
    p.dims = std::move(dims);
    return p;
}

const std::vector<std::string> kTestpod1Fields = {"d1", "d2", "d3", "d4", "s1", "s2", "s3", "s4", "t1", "t2", "t3", "t4"};
const std::vector<std::string> kTestpod2Fields = {"i1", "i2", "i3"};

}  // namespace

SequenceTables SequenceTables::lfsr(std::uint32_t seed) {
    SequenceTables t;
    Lfsr d(seed, "sequence_doubles");
    t.doubles.resize(7919);
    for (auto& x : t.doubles) x = d.next_uint32() / 4294967296.0;
    Lfsr u(seed, "sequence_uint32s");
    t.uint32s.resize(7727);
    for (auto& x : t.uint32s) x = u.next_uint32();
    return t;
}

std::vector<double> Ts3Values::transform_numbers(std::uint32_t seed) const {
    SequenceGen g(tables_, seed);
    std::vector<double> v(7);
    for (auto& x : v) x = g.next_double();
    return v;
}

Value Ts3Values::transform(std::uint32_t seed) const {
    return Value(NamedArray{kTransform, NumericArray::adopt<double>(transform_numbers(seed)), {}});
}

Value Ts3Values::vector3_of_transform(std::uint32_t seed) const {
    auto v = transform_numbers(seed);
    return Value(NamedArray{kVector3, NumericArray::adopt<double>(std::vector<double>(v.begin() + 4, v.end())), {}});
}

Value Ts3Values::transform_items(SequenceGen& g, std::size_t n, std::vector<std::uint32_t> dims) const {
    std::vector<double> flat;
    flat.reserve(n * 7);
    for (std::size_t i = 0; i < n; ++i) {
        auto t = transform_numbers(g.next_uint32());
        flat.insert(flat.end(), t.begin(), t.end());
    }
    return Value(NamedArray{kTransform, NumericArray::adopt<double>(std::move(flat)), std::move(dims)});
}

Value Ts3Values::transform_array(std::size_t n, std::uint32_t seed) const {
    SequenceGen g(tables_, seed);
    return transform_items(g, n, {});
}

Value Ts3Values::transform_multidim(std::uint32_t m, std::uint32_t n, std::uint32_t seed) const {
    SequenceGen g(tables_, seed);
    return transform_items(g, std::size_t{m} * n, {m, n});
}

std::vector<Value> Ts3Values::testpod2_fields(std::uint32_t seed) const {
    SequenceGen g(tables_, seed);
    std::vector<Value> f;
    f.push_back(Value::scalar<std::int8_t>(g.next_int8()));
    f.push_back(numbers<std::int8_t>(15, [&] { return g.next_int8(); }));
    const std::size_t n = g.next_uint32() % 15;
    f.push_back(numbers<std::int8_t>(n, [&] { return g.next_int8(); }));
    return f;
}

Value Ts3Values::testpod2(std::uint32_t seed) const {
    return Value(pod_array(kTestpod2, kTestpod2Fields, {testpod2_fields(seed)}));
}

Value Ts3Values::testpod2_items(SequenceGen& g, std::size_t n, std::vector<std::uint32_t> dims) const {
    std::vector<std::vector<Value>> items;
    for (std::size_t i = 0; i < n; ++i) items.push_back(testpod2_fields(g.next_uint32()));
    return Value(pod_array(kTestpod2, kTestpod2Fields, std::move(items), std::move(dims)));
}

std::vector<Value> Ts3Values::testpod1_fields(std::uint32_t seed) const {
    SequenceGen g(tables_, seed);
    auto dbl = [&] { return g.next_double(); };
    std::vector<Value> f;
    f.push_back(Value::scalar<double>(g.next_double()));  // d1
    f.push_back(numbers<double>(6, dbl));                // d2
    const std::size_t d3 = g.next_uint32() % 6;
    f.push_back(numbers<double>(d3, dbl));  // d3
    std::vector<double> d4(9);
    for (auto& x : d4) x = g.next_double();
    f.push_back(Value(MultiDimArray{{3, 3}, NumericArray::adopt<double>(std::move(d4))}));  // d4
    f.push_back(testpod2(g.next_uint32()));                                                 // s1
    f.push_back(testpod2_items(g, 8, {}));                                                  // s2
    const std::size_t s3 = g.next_uint32() % 9;
    f.push_back(testpod2_items(g, s3, {}));      // s3
    f.push_back(testpod2_items(g, 8, {2, 4}));   // s4
    f.push_back(transform(g.next_uint32()));     // t1
    f.push_back(transform_items(g, 4, {}));      // t2
    const std::size_t t3 = g.next_uint32() % 15;
    f.push_back(transform_items(g, t3, {}));      // t3
    f.push_back(transform_items(g, 8, {2, 4}));   // t4
    return f;
}

Value Ts3Values::testpod1(std::uint32_t seed) const {
    return Value(pod_array(kTestpod1, kTestpod1Fields, {testpod1_fields(seed)}));
}

Value Ts3Values::testpod1_array(std::size_t n, std::uint32_t seed) const {
    SequenceGen g(tables_, seed);
    std::vector<std::vector<Value>> items;
    for (std::size_t i = 0; i < n; ++i) items.push_back(testpod1_fields(g.next_uint32()));
    return Value(pod_array(kTestpod1, kTestpod1Fields, std::move(items)));
}

Value Ts3Values::testpod1_multidim(std::uint32_t m, std::uint32_t n, std::uint32_t seed) const {
    SequenceGen g(tables_, seed);
    std::vector<std::vector<Value>> items;
    for (std::size_t i = 0; i < std::size_t{m} * n; ++i) items.push_back(testpod1_fields(g.next_uint32()));
    return Value(pod_array(kTestpod1, kTestpod1Fields, std::move(items), {m, n}));
}

Value Ts3Values::teststruct3(std::uint32_t seed) const {
    SequenceGen g(tables_, seed);
    auto u = [&] { return g.next_uint32(); };
    Structure s;
    s.type_name = kTs3 + ".teststruct3";
    s.set("s1", testpod1(u()));
    const std::uint32_t s2 = u();
    s.set("s2", testpod1_array(s2 % 17, s2));
    s.set("s3", testpod1_array(11, u()));
    const std::uint32_t s4 = u();
    s.set("s4", testpod1_array(s4 % 16, s4));
    s.set("s5", testpod1_multidim(3, 3, u()));
    const std::uint32_t s6 = u();
    s.set("s6", testpod1_multidim(s6 % 6, s6 % 3, s6));
    s.set("s7", Value(List{{testpod1(u())}}));
    {
        Value a = testpod1_array(2, u());
        s.set("s8", Value(List{{std::move(a), testpod1_array(4, u())}}));
    }
    {
        Value a = testpod1_multidim(2, 3, u());
        s.set("s9", Value(List{{std::move(a), testpod1_multidim(4, 5, u())}}));
    }
    s.set("s10", testpod1(u()));
    s.set("s11", testpod1_array(3, u()));
    s.set("s12", testpod1_multidim(2, 2, u()));
    s.set("s13", Value(List{{testpod1(u())}}));
    {
        Value a = testpod1_array(3, u());
        s.set("s14", Value(List{{std::move(a), testpod1_array(5, u())}}));
    }
    {
        Value a = testpod1_multidim(7, 2, u());
        s.set("s15", Value(List{{std::move(a), testpod1_multidim(5, 1, u())}}));
    }
    s.set("t1", transform(u()));
    s.set("t2", transform_array(4, u()));
    s.set("t3", transform_multidim(2, 4, u()));
    s.set("t4", transform_array(10, u()));
    s.set("t5", transform_multidim(6, 5, u()));
    s.set("t6", Value(List{{transform(u())}}));
    {
        Value a = transform_array(4, u());
        s.set("t7", Value(List{{std::move(a), transform_array(4, u())}}));
    }
    {
        Value a = transform_multidim(2, 4, u());
        s.set("t8", Value(List{{std::move(a), transform_multidim(2, 4, u())}}));
    }
    s.set("t9", Value(List{{transform(u())}}));
    {
        Value a = transform_array(3, u());
        s.set("t10", Value(List{{std::move(a), transform_array(5, u())}}));
    }
    {
        Value a = transform_multidim(7, 2, u());
        s.set("t11", Value(List{{std::move(a), transform_multidim(5, 1, u())}}));
    }
    return Value(std::move(s));
}

}  // namespace rr::testsvc

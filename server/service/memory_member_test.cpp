// Memory members at the entry level: parameters, 1-D and multi-dim reads and writes of numeric, pod and
// namedarray memories, CORE's reply quirks, bounds and direction errors.
#include "server/service/object_service_fixture.hpp"

using namespace rr;
using namespace rr::server;
using namespace rr::server::testing;

namespace {

MessageEntry mem_req(MessageEntryType type, const char* member, std::vector<std::uint64_t> pos, std::vector<std::uint64_t> count) {
    auto e = req(type, member);
    e.elements.push_back(make_array_element<std::uint64_t>("memorypos", pos));
    e.elements.push_back(make_array_element<std::uint64_t>("count", count));
    return e;
}

MessageEntry param(const char* member, const char* name) {
    auto e = req(MessageEntryType::MemoryGetParam, member);
    e.elements.push_back(make_string_element("parameter", name));
    return e;
}

PodArray samples(std::initializer_list<double> ts) {
    PodArray p;
    p.type_name = "example.objtest.Sample";
    p.field_names = {"t", "ids"};
    for (double t : ts) (void)p.push_back({Value::scalar(t), Value::array<std::int32_t>({int(t), -int(t)})});
    return p;
}

}  // namespace

TEST_CASE("memory: numeric 1-D read, write (answered with 1172), parameters, bounds") {
    ServiceFixture f([](ServiceFixture& f) {
        REQUIRE(f.root->memory("buf").value()->set_contents(Value::array<double>({0, 1, 2, 3, 4, 5, 6, 7})));
        REQUIRE(f.root->memory("rom").value()->set_contents(Value::array<std::uint8_t>({1, 2, 3})));
    });
    auto buf = f.root->memory("buf").value();
    std::atomic<int> writes{0};
    buf->on_write([&](const SessionRef&, const std::vector<std::uint64_t>& pos, const std::vector<std::uint64_t>& count) {
        CHECK(pos == std::vector<std::uint64_t>{2});
        CHECK(count == std::vector<std::uint64_t>{3});
        ++writes;
    });
    auto c = f.connect();

    CHECK(scalar_of<std::uint64_t>(c.ok(param("buf", "Length")), "return") == 8);
    CHECK(scalar_of<std::uint32_t>(c.ok(param("buf", "MaxTransferSize")), "return") == 102400);
    CHECK(c.error(param("buf", "Dimensions")).type == MessageErrorType::InvalidOperation);
    CHECK(c.error(param("buf", "Bogus")).message == "Unknown parameter");

    auto r = c.ok(mem_req(MessageEntryType::MemoryRead, "buf", {2}, {3}));
    CHECK(r.entry_type == MessageEntryType::MemoryReadRet);
    CHECK(scalar_of<std::uint64_t>(r, "memorypos") == 2);
    CHECK(scalar_of<std::uint64_t>(r, "count") == 3);
    CHECK(read_array<double>(*r.find("data")) == std::vector<double>{2, 3, 4});

    auto w = mem_req(MessageEntryType::MemoryWrite, "buf", {2}, {3});
    w.elements.push_back(make_array_element<double>("data", std::vector<double>{-1, -2, -3}));
    auto wr = c.ok(w);
    CHECK(wr.entry_type == MessageEntryType::MemoryReadRet);  // sic, as CORE
    CHECK(scalar_of<std::uint64_t>(wr, "count") == 3);
    CHECK_FALSE(wr.find("data"));
    CHECK(writes == 1);
    CHECK(read_array<double>(*c.ok(mem_req(MessageEntryType::MemoryRead, "buf", {0}, {8})).find("data")) ==
          std::vector<double>{0, 1, -1, -2, -3, 5, 6, 7});
    CHECK(buf->contents() == Value::array<double>({0, 1, -1, -2, -3, 5, 6, 7}));

    SECTION("bounds, short data, wrong types, direction") {
        auto oor = c.error(mem_req(MessageEntryType::MemoryRead, "buf", {6}, {3}));
        CHECK(oor.type == MessageErrorType::OutOfRange);
        CHECK(oor.message == "Index out of range");
        CHECK(c.error(mem_req(MessageEntryType::MemoryRead, "buf", {9}, {0})).type == MessageErrorType::OutOfRange);
        CHECK(c.error(mem_req(MessageEntryType::MemoryRead, "buf", {~std::uint64_t{0}}, {2})).type == MessageErrorType::OutOfRange);
        CHECK(read_array<double>(*c.ok(mem_req(MessageEntryType::MemoryRead, "buf", {8}, {0})).find("data")).empty());
        auto short_data = mem_req(MessageEntryType::MemoryWrite, "buf", {0}, {2});
        short_data.elements.push_back(make_scalar_element("data", 1.0));
        CHECK(c.error(short_data).type == MessageErrorType::OutOfRange);
        auto wrong = mem_req(MessageEntryType::MemoryWrite, "buf", {0}, {1});
        wrong.elements.push_back(make_scalar_element<std::int32_t>("data", 1));
        CHECK(c.error(wrong).type == MessageErrorType::DataTypeError);
        auto pos32 = req(MessageEntryType::MemoryRead, "buf");
        pos32.elements.push_back(make_scalar_element<std::uint32_t>("memorypos", 0));
        pos32.elements.push_back(make_scalar_element<std::uint64_t>("count", 1));
        CHECK(c.error(pos32).type == MessageErrorType::DataTypeMismatch);
        CHECK(c.error(req(MessageEntryType::MemoryRead, "buf")).type == MessageErrorType::MessageElementNotFound);

        auto ro = mem_req(MessageEntryType::MemoryWrite, "rom", {0}, {1});
        ro.elements.push_back(make_scalar_element<std::uint8_t>("data", 9));
        CHECK(c.error(ro).type == MessageErrorType::ReadOnlyMember);
        CHECK(read_array<std::uint8_t>(*c.ok(mem_req(MessageEntryType::MemoryRead, "rom", {1}, {2})).find("data")) ==
              std::vector<std::uint8_t>{2, 3});
        CHECK(c.error(mem_req(MessageEntryType::MemoryRead, "value", {0}, {1})).type == MessageErrorType::MemberNotFound);
        // no contents yet
        CHECK(c.error(mem_req(MessageEntryType::MemoryRead, "pods", {0}, {1})).type == MessageErrorType::ValueNotSet);
        CHECK_FALSE(buf->set_contents(Value::array<std::int32_t>({1})));
        CHECK_FALSE(buf->set_contents(Value("x")));
    }
}

TEST_CASE("memory: multi-dim numeric blocks, column-major, CORE's count quirk") {
    ServiceFixture f([](ServiceFixture& f) {
        // 3 x 4, value = 10*row + col, column-major
        std::vector<std::int32_t> v;
        for (int col = 0; col < 4; ++col)
            for (int row = 0; row < 3; ++row) v.push_back(10 * row + col);
        REQUIRE(f.root->memory("grid").value()->set_contents(Value(MultiDimArray{{3, 4}, NumericArray::from<std::int32_t>(std::span<const std::int32_t>(v))})));
    });
    auto c = f.connect();
    CHECK(read_array<std::uint64_t>(*c.ok(param("grid", "Dimensions")).find("return")) == std::vector<std::uint64_t>{3, 4});
    CHECK(scalar_of<std::uint64_t>(c.ok(param("grid", "DimCount")), "return") == 2);
    CHECK(c.error(param("grid", "Length")).type == MessageErrorType::InvalidOperation);

    auto r = c.ok(mem_req(MessageEntryType::MemoryRead, "grid", {1, 1}, {2, 3}));
    CHECK(read_array<std::uint64_t>(*r.find("memorypos")) == std::vector<std::uint64_t>{1, 1});
    CHECK(read_array<std::uint64_t>(*r.find("count")) == std::vector<std::uint64_t>{1, 1});  // memorypos, as CORE
    auto block = f.unpack(*r.find("data"), "int32[*]");
    CHECK(block == Value(MultiDimArray{{2, 3}, NumericArray::from<std::int32_t>({11, 21, 12, 22, 13, 23})}));

    auto w = mem_req(MessageEntryType::MemoryWrite, "grid", {0, 2}, {2, 2});
    w.elements.push_back(f.pack(Value(MultiDimArray{{2, 2}, NumericArray::from<std::int32_t>({-1, -2, -3, -4})}), "int32[*]", "data"));
    auto wr = c.ok(w);
    CHECK(wr.entry_type == MessageEntryType::MemoryReadRet);
    CHECK(read_array<std::uint64_t>(*wr.find("count")) == std::vector<std::uint64_t>{2, 2});
    auto all = f.unpack(*c.ok(mem_req(MessageEntryType::MemoryRead, "grid", {0, 0}, {3, 4})).find("data"), "int32[*]");
    CHECK(all == Value(MultiDimArray{{3, 4}, NumericArray::from<std::int32_t>({0, 10, 20, 1, 11, 21, -1, -2, 22, -3, -4, 23})}));

    CHECK(c.error(mem_req(MessageEntryType::MemoryRead, "grid", {2, 0}, {2, 1})).type == MessageErrorType::OutOfRange);
    CHECK(c.error(mem_req(MessageEntryType::MemoryRead, "grid", {0}, {1})).type == MessageErrorType::OutOfRange);
    auto small = mem_req(MessageEntryType::MemoryWrite, "grid", {0, 0}, {2, 2});
    small.elements.push_back(f.pack(Value(MultiDimArray{{1, 2}, NumericArray::from<std::int32_t>({1, 2})}), "int32[*]", "data"));
    CHECK(c.error(small).type == MessageErrorType::OutOfRange);
}

TEST_CASE("memory: pod and namedarray memories") {
    ServiceFixture f([](ServiceFixture& f) {
        REQUIRE(f.root->memory("pods").value()->set_contents(Value(samples({1, 2, 3, 4}))));
        // 2 x 2 V2 items, column-major
        REQUIRE(f.root->memory("nas").value()->set_contents(
            Value(NamedArray{"example.objtest.V2", NumericArray::from<double>({1, 1, 2, 2, 3, 3, 4, 4}), {2, 2}})));
    });
    auto c = f.connect();
    CHECK(scalar_of<std::uint64_t>(c.ok(param("pods", "Length")), "return") == 4);
    auto r = c.ok(mem_req(MessageEntryType::MemoryRead, "pods", {1}, {2}));
    CHECK(r.find("data")->type == DataTypes::pod_array_t);
    CHECK(f.unpack(*r.find("data"), "Sample[]") == Value(samples({2, 3})));
    auto w = mem_req(MessageEntryType::MemoryWrite, "pods", {3}, {1});
    w.elements.push_back(f.pack(Value(samples({9})), "Sample[]", "data"));
    c.ok(w);
    CHECK(f.unpack(*c.ok(mem_req(MessageEntryType::MemoryRead, "pods", {0}, {4})).find("data"), "Sample[]") ==
          Value(samples({1, 2, 3, 9})));

    auto nr = c.ok(mem_req(MessageEntryType::MemoryRead, "nas", {0, 1}, {2, 1}));
    CHECK(nr.find("data")->type == DataTypes::namedarray_multidimarray_t);
    CHECK(f.unpack(*nr.find("data"), "V2[*]") == Value(NamedArray{"example.objtest.V2", NumericArray::from<double>({3, 3, 4, 4}), {2, 1}}));
    auto nw = mem_req(MessageEntryType::MemoryWrite, "nas", {1, 0}, {1, 2});
    nw.elements.push_back(f.pack(Value(NamedArray{"example.objtest.V2", NumericArray::from<double>({-2, -2, -4, -4}), {1, 2}}), "V2[*]", "data"));
    c.ok(nw);
    CHECK(f.root->memory("nas").value()->contents() ==
          Value(NamedArray{"example.objtest.V2", NumericArray::from<double>({1, 1, -2, -2, 3, 3, -4, -4}), {2, 2}}));
}

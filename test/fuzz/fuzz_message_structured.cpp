// Structure-aware libFuzzer target for the message codec. Random bytes rarely get past the header
// checks (magic, sizes, counts), so LLVMFuzzerCustomMutator works on the message model instead: it
// decodes the input (or starts from a small call message), changes the model — element data, types,
// names, numbers and nesting; entries and their fields; header fields, message version and string
// tables — and encodes it again. The mutated bytes are valid messages with unusual contents, and one
// mutation in eight is a plain byte mutation of the encoded message, which breaks the structure in
// one place. Each input runs the checks of fuzz_message_reader (message_checks.hpp) and unpacks every
// element as a varvalue without a service definition (core/value: what the gateway does with values
// from devices), which must not crash.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "core/json/element_json_plan.hpp"
#include "core/json/element_json_text.hpp"
#include "core/json/value_json.hpp"
#include "base/message/string_table.hpp"
#include "core/value/pack_value.hpp"
#include "core/value/var_type.hpp"
#include "robdef/service_definition_set.hpp"
#include "test/fuzz/message_checks.hpp"
#include "test/fuzz/plan_types.hpp"

extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t max_size);

namespace {

using namespace rr;

constexpr DataTypes kElementTypes[] = {
    DataTypes::void_t,      DataTypes::double_t,          DataTypes::single_t,
    DataTypes::int8_t,      DataTypes::uint8_t,           DataTypes::int16_t,
    DataTypes::uint16_t,    DataTypes::int32_t,           DataTypes::uint32_t,
    DataTypes::int64_t,     DataTypes::uint64_t,          DataTypes::string_t,
    DataTypes::cdouble_t,   DataTypes::csingle_t,         DataTypes::bool_t,
    DataTypes::structure_t, DataTypes::vector_t,          DataTypes::dictionary_t,
    DataTypes::list_t,      DataTypes::pod_t,             DataTypes::pod_array_t,
    DataTypes::pod_multidimarray_t, DataTypes::namedarray_array_t,
    DataTypes::namedarray_multidimarray_t, DataTypes::multidimarray_t,
};

constexpr std::uint16_t kEntryTypes[] = {
    0,    1,    2,    3,    4,    101,  102,  103,  104,  105,  106,  107,  108,  109,  110,  111,  112,
    113,  114,  115,  116,  117,  118,  119,  120,  121,  122,  501,  502,  1101, 1102, 1105, 1106, 1107,
    1108, 1109, 1110, 1111, 1112, 1113, 1114, 1121, 1122, 1123, 1124, 1131, 1132, 1141, 1142, 1143, 1144,
    1145, 1146, 1147, 1148, 1151, 1152, 1161, 1162, 1163, 1164, 1165, 1166, 1167, 1168, 1171, 1172, 1173,
    1174, 1175, 1176, 1181, 1182, 1183, 1184, 1185, 1186, 11161, 11162, 11163, 11164};

// Names that mean something to the layers above (member names, element names of CORE's requests,
// type names, string-table entries) next to random ones.
const char* const kNames[] = {"",          "value",      "parameter", "return",    "index",    "dims",
                              "array",     "servicedef", "objecttype", "nodeid",   "nodename", "errorname",
                              "errorstring", "packet",   "x",         "svc.S",     "svc.P",    "demo.Point",
                              "RobotRaconteurServiceIndex.NodeInfo", "experimental.create.create_obj",
                              "com.robotraconteur.geometry.Pose", "$", "a.b.c.d.e.f", "svc.N", "svc.W"};

class Mutator {
public:
    explicit Mutator(unsigned seed) : rng_(seed) {}

    std::size_t pick(std::size_t n) { return n ? std::uniform_int_distribution<std::size_t>(0, n - 1)(rng_) : 0; }
    bool coin(unsigned one_in) { return pick(one_in) == 0; }

    // `old` (at most `max` bytes) mutated by libFuzzer.
    std::string bytes(const std::string& old, std::size_t max) {
        std::string s = old.substr(0, max);
        const std::size_t len = std::max<std::size_t>(s.size(), 1);
        s.resize(max);
        s.resize(LLVMFuzzerMutate(reinterpret_cast<std::uint8_t*>(s.data()), len, max));
        return s;
    }

    std::string name(const std::string& old) {
        if (coin(2)) return kNames[pick(std::size(kNames))];
        return bytes(old, old.size() + 16);
    }

    SharedBytes data_for(DataTypes t, const SharedBytes& old) {
        const std::size_t item = std::max<std::size_t>(data_type_size(t), 1);
        std::vector<std::uint8_t> v(old.size());
        if (old.size()) std::memcpy(v.data(), old.data(), old.size());
        std::size_t max = std::min<std::size_t>(v.size() + 64, 4096);
        if (coin(8)) max = std::min<std::size_t>(item * (1 + pick(512)), 1u << 16);  // a large array now and then
        v.resize(std::max<std::size_t>(max, 1));
        std::size_t n = LLVMFuzzerMutate(v.data(), std::max<std::size_t>(old.size(), 1), v.size());
        if (coin(4)) n = item * pick(9);  // short counts, 0 included
        n -= n % item;
        v.resize(std::min(n, v.size()));
        return SharedBytes::copy_of(std::as_bytes(std::span<const std::uint8_t>(v)));
    }

    MessageElement random_element(int depth) {
        MessageElement e;
        e.name = kNames[pick(std::size(kNames))];
        retype(e, depth);
        return e;
    }

    void retype(MessageElement& e, int depth) {
        e.type = kElementTypes[pick(std::size(kElementTypes))];
        if (is_nested(e.type) && depth > 6) e.type = DataTypes::int32_t;
        e.elements.clear();
        e.data = {};
        if (is_nested(e.type)) {
            if (coin(2)) e.type_name = kNames[pick(std::size(kNames))];
            const std::size_t n = pick(4);
            for (std::size_t i = 0; i < n; ++i) {
                auto child = random_element(depth + 1);
                if (e.type == DataTypes::list_t || e.type == DataTypes::vector_t || e.type == DataTypes::pod_array_t)
                    child.number = static_cast<std::int32_t>(coin(4) ? pick(100) : i);
                e.elements.push_back(std::move(child));
            }
        } else if (e.type != DataTypes::void_t) {
            e.type_name.clear();
            e.data = data_for(e.type, {});
        }
    }

    // Visits a random element of the tree (depth-first index); nullptr when there is none.
    MessageElement* random_in(std::vector<MessageElement>& list, int& depth) {
        std::vector<std::pair<MessageElement*, int>> all;
        collect(list, 0, all);
        if (all.empty()) return nullptr;
        auto [e, d] = all[pick(all.size())];
        depth = d;
        return e;
    }

    void mutate_element(MessageElement& e, int depth) {
        switch (pick(9)) {
            case 0: retype(e, depth); break;
            case 1: e.name = name(e.name); e.name_code.reset(); break;
            case 2: e.type_name = name(e.type_name); e.type_name_code.reset(); break;
            case 3:
                if (coin(2)) e.number.reset();
                else e.number = static_cast<std::int32_t>(coin(2) ? pick(8) : rng_());
                break;
            case 4: e.metadata = bytes(e.metadata, 32); break;
            case 5: e.extended = bytes(e.extended, 32); break;
            case 6:
                if (is_nested(e.type)) {
                    if (!e.elements.empty() && coin(2)) e.elements.erase(e.elements.begin() + pick(e.elements.size()));
                    else if (depth < 8) e.elements.push_back(random_element(depth + 1));
                } else if (e.type != DataTypes::void_t) {
                    e.data = data_for(e.type, e.data);
                }
                break;
            case 7:  // wrap in a container, as a value nested one level deeper
                if (depth < 8) {
                    MessageElement outer;
                    outer.name = e.name;
                    outer.type = coin(2) ? DataTypes::list_t : DataTypes::structure_t;
                    e.name = outer.type == DataTypes::list_t ? "" : "value";
                    if (outer.type == DataTypes::list_t) e.number = 0;
                    outer.elements.push_back(std::move(e));
                    e = std::move(outer);
                }
                break;
            default:
                if (e.type != DataTypes::void_t && !is_nested(e.type)) e.data = data_for(e.type, e.data);
                break;
        }
    }

    void mutate_entry(MessageEntry& en) {
        switch (pick(8)) {
            case 0: en.entry_type = static_cast<MessageEntryType>(kEntryTypes[pick(std::size(kEntryTypes))]); break;
            case 1: en.service_path = name(en.service_path); en.service_path_code.reset(); break;
            case 2: en.member_name = name(en.member_name); en.member_name_code.reset(); break;
            case 3: en.request_id = coin(2) ? static_cast<std::uint32_t>(pick(4)) : static_cast<std::uint32_t>(rng_()); break;
            case 4: en.error = static_cast<MessageErrorType>(coin(2) ? 0 : pick(60)); break;
            case 5: en.metadata = bytes(en.metadata, 32); break;
            case 6: en.extended = bytes(en.extended, 32); break;
            default:
                if (en.elements.empty() || coin(4)) en.elements.push_back(random_element(1));
                else en.elements.erase(en.elements.begin() + pick(en.elements.size()));
                break;
        }
    }

    void mutate_header(Message& m) {
        auto& h = m.header;
        switch (pick(9)) {
            case 0: m.version = m.version == 2 ? 4 : 2; h.v4_flags.reset(); break;
            case 1: h.sender_endpoint = static_cast<std::uint32_t>(rng_()); break;
            case 2: h.receiver_endpoint = coin(2) ? 0 : static_cast<std::uint32_t>(rng_()); break;
            case 3: h.sender_node_name = name(h.sender_node_name); break;
            case 4: h.receiver_node_name = name(h.receiver_node_name); break;
            case 5: h.metadata = bytes(h.metadata, 48); break;
            case 6:
                h.message_id = static_cast<std::uint16_t>(rng_());
                h.message_res_id = static_cast<std::uint16_t>(coin(2) ? 0 : rng_());
                break;
            case 7:
                if (m.version == 4) {
                    h.priority = static_cast<std::uint16_t>(pick(3));
                    h.extended = bytes(h.extended, 16);
                }
                break;
            default: {
                NodeID::Bytes b{};
                for (auto& x : b) x = static_cast<std::byte>(rng_());
                (coin(2) ? h.sender_node_id : h.receiver_node_id) = NodeID(b);
                break;
            }
        }
    }

    void mutate(Message& m) {
        const std::size_t rounds = 1 + pick(3);
        for (std::size_t r = 0; r < rounds; ++r) {
            const std::size_t what = pick(10);
            if (what < 5) {  // elements get most of the attention
                if (m.entries.empty()) m.entries.emplace_back();
                auto& en = m.entries[pick(m.entries.size())];
                int depth = 0;
                if (auto* e = random_in(en.elements, depth)) mutate_element(*e, depth);
                else en.elements.push_back(random_element(1));
            } else if (what < 8) {
                if (m.entries.empty() || coin(6)) {
                    if (m.entries.size() < 8) m.entries.push_back(m.entries.empty() ? MessageEntry{} : m.entries[pick(m.entries.size())]);
                } else {
                    mutate_entry(m.entries[pick(m.entries.size())]);
                }
            } else {
                mutate_header(m);
            }
        }
        if (m.version == 4 && coin(4)) {
            clear_string_table_codes(m);
            apply_string_table(m, StringTableOptions{coin(2), coin(2)});
        } else if (coin(8)) {
            clear_string_table_codes(m);
        }
    }

private:
    static void collect(std::vector<MessageElement>& list, int depth, std::vector<std::pair<MessageElement*, int>>& out) {
        for (auto& e : list) {
            out.emplace_back(&e, depth);
            collect(e.elements, depth + 1, out);
        }
    }

    std::minstd_rand rng_;
};

Message starting_message() {
    Message m;
    m.version = 4;
    m.header.sender_endpoint = 1000;
    m.header.receiver_endpoint = 2000;
    MessageEntry e;
    e.entry_type = MessageEntryType::FunctionCallReq;
    e.service_path = "svc.obj";
    e.member_name = "f";
    e.request_id = 1;
    m.entries.push_back(std::move(e));
    return m;
}

}  // namespace

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t max_size,
                                               unsigned int seed) {
    Mutator mut(seed);
    if (mut.coin(8)) return LLVMFuzzerMutate(data, size, max_size);  // break the structure in one place
    auto decoded = decode_message(SharedBytes::copy_of(rr::fuzz::as_bytes(data, size)), rr::fuzz::roomy_limits());
    Message m = decoded ? std::move(*decoded) : starting_message();
    if (decoded) m.header.v4_flags.reset();  // routing omission flags would refuse most changes
    mut.mutate(m);
    auto bytes = encode_message(m);
    if (!bytes || bytes->size() > max_size) return LLVMFuzzerMutate(data, size, max_size);
    std::memcpy(data, bytes->data(), bytes->size());
    return bytes->size();
}

// A numeric element as JSON text: the gateway's direct path writes what the general path (unpack_value,
// value_to_json, nlohmann's dump) does, and declines exactly what the general path refuses.
void check_json_text(const MessageElement& el) {
    if (!is_numeric(el.type)) return;
    static const robdef::ServiceDefinitionSet no_types;
    for (auto array : {robdef::ArrayKind::array, robdef::ArrayKind::none}) {
        robdef::TypeDefinition t;
        t.base = el.type;
        t.array = array;
        t.array_var_length = true;
        std::string direct;
        const bool rendered = element_json_text::append(direct, el, t);
        auto v = unpack_value(el, t, no_types, "");
        if (!v) {
            if (rendered) __builtin_trap();
            continue;
        }
        auto j = value_to_json(*v, t, no_types, "");
        if (!j || !rendered) __builtin_trap();
        if (direct != j->dump(-1, ' ', false, nlohmann::json::error_handler_t::replace)) __builtin_trap();
    }
}

// Any element as each of a few types through the plan: the text is the general path's, and there is no
// text where the general path refuses the element (the plan may decline more).
void check_json_plan(const MessageElement& el) {
    struct Typed {
        robdef::TypeDefinition type;
        std::shared_ptr<const element_json_text::Plan> plan;
    };
    static const robdef::ServiceDefinitionSet set = [] {
        robdef::ServiceDefinitionSet s;
        if (!s.add_text(rr::fuzz::kPlanRobdef, "fuzz.robdef")) __builtin_trap();
        return s;
    }();
    static const std::vector<Typed> typed = [] {
        std::vector<Typed> out;
        for (const char* text : {"S", "W", "P[]", "N[]", "N", "string", "int32{list}", "string{string}", "double[*]", "E", "P"}) {
            auto t = parse_type_string(text);
            if (!t) __builtin_trap();
            auto plan = element_json_text::Plan::compile(*t, set, "svc");
            if (!plan) __builtin_trap();
            out.push_back({*t, plan});
        }
        return out;
    }();
    for (const auto& [type, plan] : typed) {
        std::string direct;
        const bool rendered = plan->append(direct, el);
        auto v = unpack_value(el, type, set, "svc");
        if (!v) {
            if (rendered) __builtin_trap();
            continue;
        }
        auto j = value_to_json(*v, type, set, "svc");
        if (!j) {
            if (rendered) __builtin_trap();
            continue;
        }
        if (rendered && direct != j->dump(-1, ' ', false, nlohmann::json::error_handler_t::replace)) __builtin_trap();
    }
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    rr::fuzz::check_message_input(data, size);
    // Values from a peer, without a definition: varvalue unpacking must fail cleanly or succeed.
    Limits limits;
    limits.max_elements = 1u << 16;
    auto m = decode_message(SharedBytes::copy_of(rr::fuzz::as_bytes(data, size)), rr::fuzz::fuzz_limits());
    if (m)
        for (const auto& en : m->entries)
            for (const auto& el : en.elements) {
                (void)unpack_value_untyped(el, limits);
                check_json_text(el);
                check_json_plan(el);
            }
    return 0;
}

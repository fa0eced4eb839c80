#include "test/testsvc/test_values.hpp"

#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/json/value_json.hpp"
#include "robdef/parser.hpp"
#include "test/testsvc/value_fill.hpp"

namespace rr::testsvc {
namespace {

constexpr std::size_t kMaxFileBytes = 64u * 1024u * 1024u;

std::string service_of(const std::string& qualified) { return qualified.substr(0, qualified.rfind('.')); }

RRError bad(const std::string& path, const std::string& what) {
    return make_error(MessageErrorType::InvalidArgument, path + ": " + what);
}

}  // namespace

TestValues::TestValues(std::shared_ptr<const server::ServiceTypes> types, std::uint32_t seed)
    : types_(std::move(types)), seed_(seed), sequence_(SequenceTables::lfsr(seed)) {}

const robdef::MemberDefinition* TestValues::property_def(const std::string& object_type,
                                                         const std::string& property) const {
    const auto* obj = types_->find_object(object_type);
    if (!obj) return nullptr;
    const auto* m = obj->find_member(property);
    return m && m->kind == robdef::MemberKind::property ? m : nullptr;
}

Result<Value> TestValues::get(const std::string& object_type, const std::string& property) const {
    if (auto it = properties_.find({object_type, property}); it != properties_.end() && it->second.get)
        return *it->second.get;
    const auto* m = property_def(object_type, property);
    if (!m) return fail(MessageErrorType::MemberNotFound, "no property " + object_type + "." + property);
    Lfsr g(seed_, property + "_get");
    return lfsr_value(m->type, g, types_->set(), service_of(object_type));
}

Result<std::optional<Value>> TestValues::expected_set(const std::string& object_type, const std::string& property) const {
    if (auto it = properties_.find({object_type, property}); it != properties_.end()) {
        if (it->second.set) return std::optional<Value>(*it->second.set);
        return std::optional<Value>();  // named by the official values, with no value to compare
    }
    const auto* m = property_def(object_type, property);
    if (!m) return fail(MessageErrorType::MemberNotFound, "no property " + object_type + "." + property);
    Lfsr g(seed_, property + "_set");
    auto v = lfsr_value(m->type, g, types_->set(), service_of(object_type));
    if (!v) return v.take_error();
    return std::optional<Value>(std::move(*v));
}

std::optional<Value> TestValues::memory(const std::string& object_type, const std::string& memory) const {
    auto it = memories_.find({object_type, memory});
    if (it == memories_.end()) return std::nullopt;
    return it->second;
}

Result<Value> TestValues::lfsr(std::string_view type, const std::string& key) const {
    auto t = robdef::parse_type(type);
    if (!t) return t.take_error();
    Lfsr g(seed_, key);
    return lfsr_value(*t, g, types_->set(), {});
}

Result<TestValues> TestValues::load_official(std::shared_ptr<const server::ServiceTypes> types, const std::string& path,
                                             std::uint32_t seed) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return fail(MessageErrorType::IOError, "cannot read " + path);
    std::ostringstream text;
    text << in.rdbuf();
    if (text.str().size() > kMaxFileBytes) return fail(bad(path, "larger than 64 MiB"));
    auto doc = nlohmann::json::parse(text.str(), nullptr, false);
    if (doc.is_discarded() || !doc.is_object()) return fail(bad(path, "not a JSON object"));
    if (doc.value("format", std::string()) != "rr-testsvc-official-values 1")
        return fail(bad(path, "format is not \"rr-testsvc-official-values 1\""));

    TestValues v(types, seed);
    v.official_ = true;
    const auto& objects = doc.value("objects", nlohmann::json::object());
    if (!objects.is_object()) return fail(bad(path, "\"objects\" is not an object"));
    for (const auto& [type, body] : objects.items()) {
        const auto* obj = types->find_object(type);
        if (!obj) return fail(bad(path, "unknown object type " + type));
        if (!body.is_object()) return fail(bad(path, type + " is not an object"));
        const std::string svc = service_of(type);
        const auto& props = body.value("properties", nlohmann::json::object());
        for (const auto& [name, pv] : props.items()) {
            const auto* m = obj->find_member(name);
            if (!m || m->kind != robdef::MemberKind::property) return fail(bad(path, type + " has no property " + name));
            if (!pv.is_object()) return fail(bad(path, type + "." + name + " is not an object"));
            Entry e;
            for (const char* which : {"get", "set"}) {
                if (!pv.contains(which)) continue;
                auto val = value_from_json(pv.at(which), m->type, types->set(), svc);
                if (!val) return fail(bad(path, type + "." + name + "." + which + ": " + val.error().message));
                (std::string_view(which) == "get" ? e.get : e.set) = std::move(*val);
            }
            v.properties_[{type, name}] = std::move(e);
        }
        const auto& mems = body.value("memories", nlohmann::json::object());
        for (const auto& [name, mv] : mems.items()) {
            const auto* m = obj->find_member(name);
            if (!m || m->kind != robdef::MemberKind::memory) return fail(bad(path, type + " has no memory " + name));
            auto val = value_from_json(mv, m->type, types->set(), svc);
            if (!val) return fail(bad(path, type + "." + name + ": " + val.error().message));
            v.memories_[{type, name}] = std::move(*val);
        }
    }
    if (doc.contains("sequence")) {
        const auto& seq = doc.at("sequence");
        SequenceTables t;
        try {
            t.doubles = seq.at("doubles").get<std::vector<double>>();
            t.uint32s = seq.at("uint32s").get<std::vector<std::uint32_t>>();
        } catch (const nlohmann::json::exception& e) {
            return fail(bad(path, std::string("\"sequence\": ") + e.what()));
        }
        if (t.doubles.empty() || t.uint32s.empty()) return fail(bad(path, "\"sequence\" tables are empty"));
        v.sequence_ = std::move(t);
    }
    return v;
}

}  // namespace rr::testsvc

// Where rr-test-service takes the values of its properties and memories, and the tables of the
// TestService3 recipes (sequence_gen.hpp):
//
//   LFSR (default)    a get of property P of an object returns lfsr_value(type of P, Lfsr(seed, "P_get"));
//                     a set must send lfsr_value(type, Lfsr(seed, "P_set")) (else InvalidArgument);
//                     memories start from Lfsr(seed, "<memory>_init") where a test needs contents;
//                     the recipe tables are SequenceTables::lfsr(seed). test/testsvc/testsvc_checks.py
//                     computes the same values in Python.
//   official values   a file made by test/testsvc/official_values.py from a checkout of the official
//                     repository (never kept in this one): the values the official test services
//                     return and expect, so the official client suite (test/python) passes. Its
//                     properties replace the LFSR ones (a property the file does not name keeps its
//                     LFSR value); a set the file gives no value for accepts any value of the type.
//
// The file (JSON; values in the project's JSON mapping, docs/json-mapping.md, typed by the robdef):
//   {"format": "rr-testsvc-official-values 1", "source": "…",
//    "objects": {"<qualified object type>": {"properties": {"<name>": {"get": v, "set": v}},
//                                            "memories": {"<name>": v}}},
//    "sequence": {"doubles": [...], "uint32s": [...]}}
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "core/value/value.hpp"
#include "server/service/service_types.hpp"
#include "test/testsvc/sequence_gen.hpp"

namespace rr::testsvc {

class TestValues {
public:
    static constexpr std::uint32_t kSeed = 55;  // issue 55

    /// LFSR values for the definitions in `types`.
    explicit TestValues(std::shared_ptr<const server::ServiceTypes> types, std::uint32_t seed = kSeed);
    /// LFSR values, with those of the official values file at `path` on top. Errors: IOError (cannot
    /// read), InvalidArgument (not such a file: bad JSON, format, unknown object or member, a value
    /// that does not fit its robdef type; the message names the place).
    static Result<TestValues> load_official(std::shared_ptr<const server::ServiceTypes> types, const std::string& path,
                                            std::uint32_t seed = kSeed);

    bool official() const noexcept { return official_; }
    std::uint32_t seed() const noexcept { return seed_; }

    /// What a get of `property` (of object type `object_type`, qualified) returns.
    /// Errors: MemberNotFound (no such property); lfsr_value's errors.
    Result<Value> get(const std::string& object_type, const std::string& property) const;
    /// What a set of `property` must send; nullopt: any value of the type.
    Result<std::optional<Value>> expected_set(const std::string& object_type, const std::string& property) const;
    /// The starting contents the file gives a memory, if any.
    std::optional<Value> memory(const std::string& object_type, const std::string& memory) const;
    /// Values drawn from Lfsr(seed, key) by the type text `type` (e.g. "double[]", qualified names),
    /// for members whose values are not properties (memory contents).
    Result<Value> lfsr(std::string_view type, const std::string& key) const;

    const SequenceTables& sequence() const noexcept { return sequence_; }

private:
    struct Entry {
        std::optional<Value> get, set;
    };
    const robdef::MemberDefinition* property_def(const std::string& object_type, const std::string& property) const;

    std::shared_ptr<const server::ServiceTypes> types_;
    std::uint32_t seed_;
    bool official_ = false;
    std::map<std::pair<std::string, std::string>, Entry> properties_;  // (object type, property)
    std::map<std::pair<std::string, std::string>, Value> memories_;
    SequenceTables sequence_;
};

}  // namespace rr::testsvc

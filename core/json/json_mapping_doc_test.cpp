// Runs every example of docs/json-mapping.md, so the document and the code cannot drift apart.
#include <catch2/catch.hpp>

#include <fstream>
#include <sstream>

#include "core/json/value_json.hpp"
#include "core/value/pack_value.hpp"
#include "core/value/var_type.hpp"
#include "robdef/service_definition_set.hpp"

using namespace rr;
using nlohmann::json;

namespace {

struct Block {
    std::string lang;
    int line = 0;  // line of the opening fence
    std::vector<std::string> lines;
};

std::vector<Block> fenced_blocks(const std::string& text) {
    std::vector<Block> blocks;
    std::istringstream in(text);
    std::string line;
    int n = 0;
    Block* open = nullptr;
    while (std::getline(in, line)) {
        ++n;
        if (line.rfind("```", 0) == 0) {
            if (open) {
                open = nullptr;
            } else {
                blocks.push_back(Block{line.substr(3), n, {}});
                open = &blocks.back();
            }
        } else if (open) {
            open->lines.push_back(line);
        }
    }
    return blocks;
}

struct Example {
    int line = 0;
    std::string type, error, canonical, wire, body;
};

Example parse_example(const Block& b) {
    Example e;
    e.line = b.line;
    for (const auto& l : b.lines) {
        auto directive = [&](std::string_view key, std::string& out) {
            std::string prefix = "// " + std::string(key) + ":";
            if (l.rfind(prefix, 0) != 0) return false;
            out = l.substr(prefix.size());
            out.erase(0, out.find_first_not_of(' '));
            return true;
        };
        if (directive("type", e.type) || directive("error", e.error) || directive("canonical", e.canonical) ||
            directive("wire", e.wire))
            continue;
        e.body += l + "\n";
    }
    return e;
}

std::string read_doc() {
    std::ifstream f(std::string(RR_SOURCE_DIR) + "/docs/json-mapping.md");
    REQUIRE(f.good());
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

}  // namespace

TEST_CASE("docs/json-mapping.md: every example holds") {
    auto blocks = fenced_blocks(read_doc());
    robdef::ServiceDefinitionSet defs;
    std::string service;
    for (const auto& b : blocks) {
        if (b.lang != "robdef") continue;
        std::string text;
        for (const auto& l : b.lines) text += l + "\n";
        auto r = defs.add_text(text, "json-mapping.md");
        INFO((r ? std::string() : r.error().message));
        REQUIRE(r);
        service = defs.definitions().back()->name;
    }
    REQUIRE(service == "example.json");

    int examples = 0, errors = 0;
    for (const auto& b : blocks) {
        if (b.lang != "json") continue;
        Example ex = parse_example(b);
        INFO("docs/json-mapping.md:" << ex.line << "  type " << ex.type);
        REQUIRE_FALSE(ex.type.empty());  // every JSON block in the document is an example
        ++examples;
        auto type = parse_type_string(ex.type);
        REQUIRE(type);
        json input = json::parse(ex.body);
        auto value = value_from_json(input, *type, defs, service);
        if (!ex.error.empty()) {
            ++errors;
            REQUIRE_FALSE(value);
            INFO(value.error().message);
            CHECK(value.error().name == "RobotRaconteur." + ex.error);
            continue;
        }
        INFO((value ? std::string() : value.error().message));
        REQUIRE(value);
        std::string expected = (ex.canonical.empty() ? input : json::parse(ex.canonical)).dump();
        auto out = value_to_json(*value, *type, defs, service);
        INFO((out ? std::string() : out.error().message));
        REQUIRE(out);
        CHECK(out->dump() == expected);

        // Through the wire and back.
        auto element = pack_value(*value, *type, "value", defs, service);
        INFO((element ? std::string() : element.error().message));
        REQUIRE(element);
        auto back = unpack_value(*element, *type, defs, service);
        INFO((back ? std::string() : back.error().message));
        REQUIRE(back);
        auto out2 = value_to_json(*back, *type, defs, service);
        REQUIRE(out2);
        CHECK(out2->dump() == (ex.wire.empty() ? expected : json::parse(ex.wire).dump()));
    }
    CHECK(examples >= 70);
    CHECK(errors >= 25);
}

// Writes an MCAP file with one `json` channel per wire, pipe, property and event of every object of the
// service definitions under the given folders, each with the JSON Schema the recorder would write
// (server/record/json_schema.hpp), so that foxglove_json_check.mjs can check every schema against the
// rules of Foxglove's / Lichtblick's parser without recording a device.
//
//   rr_foxglove_schema_dump OUT.mcap DIR...     (exit 1 with a message when a folder or the file fails)
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "core/mcap/mcap_writer.hpp"
#include "robdef/service_definition_set.hpp"
#include "server/mcap/mcap_file.hpp"
#include "server/record/json_schema.hpp"

using namespace rr;

int main(int argc, char** argv) {
    if (argc < 3) {
        std::cerr << "usage: rr_foxglove_schema_dump OUT.mcap DIR...\n";
        return 2;
    }
    robdef::ServiceDefinitionSet set;
    for (int i = 2; i < argc; ++i) {
        std::error_code ec;
        for (std::filesystem::recursive_directory_iterator it(argv[i], ec), end; !ec && it != end; it.increment(ec)) {
            if (it->path().extension() != ".robdef") continue;
            std::ifstream in(it->path());
            std::stringstream text;
            text << in.rdbuf();
            if (auto r = set.add_text(text.str(), it->path().string()); !r)
                std::cerr << "skipped " << it->path() << ": " << r.error().message << "\n";
        }
        if (ec) {
            std::cerr << argv[i] << ": " << ec.message() << "\n";
            return 1;
        }
    }
    auto sink = mcap::FileSink::create(argv[1]);
    if (!sink) {
        std::cerr << sink.error().message << "\n";
        return 1;
    }
    mcap::McapWriter writer(**sink);
    if (auto r = writer.open(); !r) return std::cerr << r.error().message << "\n", 1;
    int channels = 0;
    for (const auto* def : set.definitions())
        for (const auto& object : def->objects)
            for (const auto& m : object.members) {
                const std::string title = def->name + "." + object.name + "." + m.name;
                nlohmann::json schema;
                switch (m.kind) {
                    case robdef::MemberKind::wire:
                        schema = server::record::wire_message_schema(m.type, set, def->name, title);
                        break;
                    case robdef::MemberKind::pipe:
                    case robdef::MemberKind::property:
                        schema = server::record::value_message_schema(m.type, set, def->name, title);
                        break;
                    case robdef::MemberKind::event:
                        schema = server::record::event_message_schema(m, set, def->name, title);
                        break;
                    default: continue;
                }
                const std::string text = schema.dump();
                auto sid = writer.add_schema(title, "jsonschema", {reinterpret_cast<const std::byte*>(text.data()), text.size()});
                if (!sid) return std::cerr << sid.error().message << "\n", 1;
                if (auto c = writer.add_channel(*sid, title, "json"); !c) return std::cerr << c.error().message << "\n", 1;
                ++channels;
            }
    if (auto r = writer.close(); !r) return std::cerr << r.error().message << "\n", 1;
    if (auto r = (*sink)->close(); !r) return std::cerr << r.error().message << "\n", 1;
    std::cerr << channels << " channels from " << set.definitions().size() << " service definitions\n";
    return channels > 0 ? 0 : 1;
}

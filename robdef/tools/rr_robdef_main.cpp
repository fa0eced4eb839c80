// rr-robdef: checks and formats Robot Raconteur service definition files.
//
//   rr-robdef check FILE...   parse all files, verify them as one set (imports resolved across the
//                             files plus the built-in RobotRaconteurServiceIndex); prints
//                             `file:line: error: message` / `file:line: warning: message`;
//                             exit status 1 on any error, else 0.
//   rr-robdef format FILE     print the canonical text form (robdef.md §12).
//
// The only robdef code that reads files; their bytes go through definition_file_text (a leading UTF-8
// byte-order mark is dropped with a warning, as the official file readers drop it: robdef.md §1.1).
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "robdef/canonical_text.hpp"
#include "robdef/parser.hpp"
#include "robdef/service_definition_set.hpp"

namespace {

int usage() {
    std::cerr << "usage: rr-robdef check FILE...\n"
                 "       rr-robdef format FILE\n";
    return 2;
}

// The file's text, its warnings printed to `warnings`; false when it cannot be read.
bool read_file(const std::string& path, std::string& out, std::ostream& warnings) {
    std::ifstream f(path, std::ios::binary);
    if (!f) return false;
    std::ostringstream ss;
    ss << f.rdbuf();
    auto file = rr::robdef::definition_file_text(ss.str(), path);
    for (const auto& d : file.diagnostics) warnings << rr::robdef::format_diagnostic(d) << '\n';
    out = std::move(file.text);
    return true;
}

int check(const std::vector<std::string>& files) {
    rr::robdef::ServiceDefinitionSet set;
    bool failed = false;
    std::vector<std::string> names;
    for (const auto& path : files) {
        std::string text;
        if (!read_file(path, text, std::cout)) {
            std::cout << path << ": error: cannot read file\n";
            failed = true;
            continue;
        }
        auto r = rr::robdef::parse_service_definition_report(text, path);
        for (const auto& d : r.diagnostics) std::cout << rr::robdef::format_diagnostic(d) << '\n';
        if (!r.ok()) {
            failed = true;
            continue;
        }
        for (const auto& n : names)
            if (n == r.definition->name) {
                std::cout << path << ":" << r.definition->location.line << ": error: Service definition \""
                          << n << "\" is defined more than once\n";
                failed = true;
            }
        names.push_back(r.definition->name);
        set.add(std::move(*r.definition));
    }
    if (failed) return 1;
    auto diags = set.verify();
    for (const auto& d : diags) std::cout << rr::robdef::format_diagnostic(d) << '\n';
    return rr::robdef::has_errors(diags) ? 1 : 0;
}

int format(const std::string& path) {
    std::string text;
    if (!read_file(path, text, std::cerr)) {
        std::cerr << path << ": error: cannot read file\n";
        return 1;
    }
    auto r = rr::robdef::parse_service_definition_report(text, path);
    if (!r.ok()) {
        for (const auto& d : r.diagnostics) std::cerr << rr::robdef::format_diagnostic(d) << '\n';
        return 1;
    }
    std::cout << rr::robdef::to_string(*r.definition);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 3) return usage();
    std::string cmd = argv[1];
    std::vector<std::string> files(argv + 2, argv + argc);
    if (cmd == "check") return check(files);
    if (cmd == "format" && files.size() == 1) return format(files[0]);
    return usage();
}

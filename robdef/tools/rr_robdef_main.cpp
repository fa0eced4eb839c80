// rr-robdef: checks and formats Robot Raconteur service definition files.
//
//   rr-robdef check FILE...   parse all files, verify them as one set (imports resolved across the
//                             files plus the built-in RobotRaconteurServiceIndex); prints
//                             `file:line: error: message` / `file:line: warning: message`;
//                             exit status 1 on any error, else 0.
//   rr-robdef format FILE     print the canonical text form (robdef.md §12).
//   rr-robdef ts [-o DIR] [-I DIR]... [--builtin NAME]... [--dts] FILE...
//                             TypeScript for the robotraconteur-wasm package (robdef/typescript.hpp):
//                             `<service>.ts` per definition into DIR (default .): types, enums and
//                             constants in one module that every build tool compiles; --dts writes
//                             `<service>.d.ts` + `<service>.js` instead (as a package ships them).
//                             --url/--gateway/--definitions (fetching a running device's definitions)
//                             belong to the package's node rr-robdef (wasm-client/src/rr_robdef.mjs).
//                             Imports are followed: `<import>.robdef` is looked for in each FILE's
//                             folder and the -I folders; one not found is an error naming it.
//                             --builtin loads a built-in definition (experimental.create,
//                             experimental.createwebcam, RobotRaconteurServiceIndex) as if it were a
//                             file. Errors as for check (exit 1); nothing is written then.
//
// The only robdef code that reads files; their bytes go through definition_file_text (a leading UTF-8
// byte-order mark is dropped with a warning, as the official file readers drop it: robdef.md §1.1).
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "robdef/builtin/experimental_create.hpp"
#include "robdef/builtin/experimental_createwebcam.hpp"
#include "robdef/builtin/service_index.hpp"
#include "robdef/canonical_text.hpp"
#include "robdef/typescript.hpp"
#include "robdef/parser.hpp"
#include "robdef/service_definition_set.hpp"

namespace {

int usage() {
    std::cerr << "usage: rr-robdef check FILE...\n"
                 "       rr-robdef format FILE\n"
                 "       rr-robdef ts [-o DIR] [-I DIR]... [--builtin NAME]... [--dts] FILE...\n";
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

// The text of a built-in definition by service name, or empty.
std::string_view builtin_text(std::string_view name) {
    if (name == rr::robdef::kExperimentalCreateServiceName) return rr::robdef::experimental_create_robdef();
    if (name == rr::robdef::kExperimentalCreateWebcamServiceName) return rr::robdef::experimental_createwebcam_robdef();
    if (name == rr::robdef::kServiceIndexServiceName) return rr::robdef::service_index_robdef();
    return {};
}

bool write_file(const std::filesystem::path& p, const std::string& text) {
    std::ofstream f(p, std::ios::binary | std::ios::trunc);
    f << text;
    return static_cast<bool>(f.flush());
}

int typescript(const std::vector<std::string>& args) {
    namespace fs = std::filesystem;
    std::string out_dir = ".";
    std::vector<std::string> files, include_dirs, builtins;
    bool dts = false;
    for (std::size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        const bool has_value = i + 1 < args.size();
        if (a == "-o" && has_value) {
            out_dir = args[++i];
        } else if (a == "-I" && has_value) {
            include_dirs.push_back(args[++i]);
        } else if (a == "--builtin" && has_value) {
            builtins.push_back(args[++i]);
        } else if (a == "--dts") {
            dts = true;
        } else if (a == "--url" || a == "--gateway" || a == "--device" || a == "--definitions") {
            // Fetching needs a client (WebSocket, HTTP): the package's rr-robdef (node) has one.
            std::cerr << "rr-robdef ts: " << a << " is an option of the robotraconteur-wasm package's rr-robdef"
                      << " (npx rr-robdef ts " << a << " ...; wasm-client/README.md \"TypeScript quickstart\");"
                      << " this one reads definition files\n";
            return 2;
        } else if (!a.empty() && a[0] == '-') {
            return usage();
        } else {
            files.push_back(a);
            include_dirs.push_back(fs::path(a).parent_path().empty() ? "." : fs::path(a).parent_path().string());
        }
    }
    if (files.empty() && builtins.empty()) return usage();

    rr::robdef::ServiceDefinitionSet set;
    std::vector<std::string> generate;  // service names, in the order loaded
    std::set<std::string> loaded{std::string(rr::robdef::kServiceIndexServiceName)};
    bool failed = false;
    auto add = [&](const std::string& text, const std::string& path) {
        auto r = rr::robdef::parse_service_definition_report(text, path);
        for (const auto& d : r.diagnostics) std::cout << rr::robdef::format_diagnostic(d) << '\n';
        if (!r.ok()) {
            failed = true;
            return;
        }
        const std::string name = r.definition->name;
        if (!loaded.insert(name).second && name != rr::robdef::kServiceIndexServiceName) {
            std::cout << path << ":" << r.definition->location.line << ": error: Service definition \"" << name
                      << "\" is defined more than once\n";
            failed = true;
            return;
        }
        generate.push_back(name);
        set.add(std::move(*r.definition));
    };
    for (const auto& b : builtins) {
        auto text = builtin_text(b);
        if (text.empty()) {
            std::cout << "--builtin " << b << ": error: no built-in definition of that name\n";
            failed = true;
            continue;
        }
        add(std::string(text), "<builtin " + b + ">");
    }
    for (const auto& path : files) {
        std::string text;
        if (!read_file(path, text, std::cout)) {
            std::cout << path << ": error: cannot read file\n";
            failed = true;
            continue;
        }
        add(text, path);
    }
    // Follow imports: `<name>.robdef` in the given files' folders and the -I folders.
    for (std::size_t k = 0; k < generate.size() && !failed; ++k) {
        const auto* def = set.find_service(generate[k]);
        for (std::size_t i = 0; def && i < def->imports.size(); ++i) {
            const std::string& imp = def->imports[i];
            if (loaded.count(imp)) continue;
            std::string found;
            for (const auto& dir : include_dirs) {
                fs::path p = fs::path(dir) / (imp + ".robdef");
                std::error_code exists_error;  // the error_code forms: the wasm build has no exceptions
                if (fs::exists(p, exists_error)) {
                    found = p.string();
                    break;
                }
            }
            const int line = i < def->import_lines.size() ? def->import_lines[i] : def->location.line;
            if (found.empty()) {
                std::string dirs;
                for (const auto& d : std::set<std::string>(include_dirs.begin(), include_dirs.end()))
                    dirs += (dirs.empty() ? "" : ", ") + d;
                std::cout << def->location.file << ":" << line << ": error: Service definition \"" << imp
                          << "\" not found (imported; no " << imp << ".robdef in " << dirs << ")\n";
                failed = true;
                break;
            }
            std::string text;
            if (!read_file(found, text, std::cout)) {
                std::cout << found << ": error: cannot read file\n";
                failed = true;
                break;
            }
            add(text, found);
            def = set.find_service(generate[k]);  // add() may move definitions: look it up again
        }
    }
    if (failed) return 1;
    auto diags = set.verify();
    for (const auto& d : diags) std::cout << rr::robdef::format_diagnostic(d) << '\n';
    if (rr::robdef::has_errors(diags)) return 1;

    std::error_code ec;
    fs::create_directories(out_dir, ec);
    for (const auto& name : generate) {
        auto mod = rr::robdef::to_typescript(*set.find_service(name), set);
        const std::string base = (fs::path(out_dir) / mod.file_stem).string();
        const bool written = dts ? write_file(base + ".d.ts", mod.declarations) && write_file(base + ".js", mod.javascript)
                                 : write_file(base + ".ts", mod.source);
        if (!written) {
            std::cout << base << (dts ? ".d.ts" : ".ts") << ": error: cannot write file\n";
            return 1;
        }
    }
    std::cerr << "rr-robdef ts: " << generate.size() << " module(s) in " << out_dir << "\n";
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 3) return usage();
    std::string cmd = argv[1];
    std::vector<std::string> files(argv + 2, argv + argc);
    if (cmd == "ts") return typescript(files);
    if (cmd == "check") return check(files);
    if (cmd == "format" && files.size() == 1) return format(files[0]);
    return usage();
}

// rr_robdef_verdicts: our verdict on service definition cases, for robdef_agreement.py (which asks the
// official library the same question and compares).
//
//   rr_robdef_verdicts CASE_DIR...
//
// Each CASE_DIR holds one case: its `*.robdef` files, read as raw bytes (text semantics: no UTF-8 BOM
// is stripped, as for a definition received over the wire) and verified together as one set with
// the built-in RobotRaconteurServiceIndex. For each case one line goes to stdout:
//
//   <CASE_DIR> TAB accept
//   <CASE_DIR> TAB parse TAB <first parse error>
//   <CASE_DIR> TAB verify TAB <first verify error>
//
// and, for every file of an accepted case, our canonical text (robdef/canonical_text.hpp) is written
// next to it as `<file>.canonical`, so that the script can check the official parser accepts what we
// would emit. Exit status 0 unless a folder cannot be read (2).
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <vector>

#include "robdef/canonical_text.hpp"
#include "robdef/parser.hpp"
#include "robdef/service_definition_set.hpp"

namespace {

namespace fs = std::filesystem;

std::string one_line(std::string s) {
    std::replace(s.begin(), s.end(), '\n', ' ');
    std::replace(s.begin(), s.end(), '\t', ' ');
    return s;
}

bool read_bytes(const fs::path& p, std::string& out) {
    std::ifstream f(p, std::ios::binary);
    if (!f) return false;
    out.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
    return true;
}

bool write_bytes(const fs::path& p, const std::string& bytes) {
    std::ofstream f(p, std::ios::binary);
    f << bytes;
    return static_cast<bool>(f);
}

int run_case(const fs::path& dir) {
    std::vector<fs::path> files;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec))
        if (e.is_regular_file() && e.path().extension() == ".robdef") files.push_back(e.path());
    if (ec || files.empty()) {
        std::cerr << "rr_robdef_verdicts: no .robdef files in " << dir << "\n";
        return 2;
    }
    std::sort(files.begin(), files.end());
    rr::robdef::ServiceDefinitionSet set;
    std::vector<std::pair<fs::path, std::string>> canonical;
    for (const auto& f : files) {
        std::string text;
        if (!read_bytes(f, text)) {
            std::cerr << "rr_robdef_verdicts: cannot read " << f << "\n";
            return 2;
        }
        auto r = rr::robdef::parse_service_definition(text, f.filename().string());
        if (!r) {
            std::cout << dir.string() << "\tparse\t" << one_line(r.error().message) << "\n";
            return 0;
        }
        canonical.emplace_back(f, rr::robdef::to_string(r->definition));
        set.add(std::move(r->definition));
    }
    for (const auto& d : set.verify()) {
        if (!d.is_error()) continue;
        std::cout << dir.string() << "\tverify\t" << one_line(rr::robdef::format_diagnostic(d)) << "\n";
        return 0;
    }
    for (const auto& [f, text] : canonical)
        if (!write_bytes(fs::path(f.string() + ".canonical"), text)) return 2;
    std::cout << dir.string() << "\taccept\n";
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::cerr << "usage: rr_robdef_verdicts CASE_DIR...\n";
        return 2;
    }
    for (int i = 1; i < argc; ++i)
        if (int rc = run_case(argv[i]); rc != 0) return rc;
    return 0;
}

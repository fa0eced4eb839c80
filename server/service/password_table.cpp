#include "server/service/password_table.hpp"

#include <openssl/evp.h>

#include <fstream>
#include <sstream>

#include "core/session/elements.hpp"
#include "server/common/digest_hex.hpp"

namespace rr::server {

namespace {

bool is_md5_hex(std::string_view s) {
    if (s.size() != 32) return false;
    for (char c : s)
        if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
    return true;
}

std::string lower(std::string_view s) {
    std::string out(s);
    for (auto& c : out)
        if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    return out;
}

std::vector<std::string> split(std::string_view s, char sep) {
    std::vector<std::string> out;
    std::size_t start = 0;
    for (std::size_t i = 0; i <= s.size(); ++i) {
        if (i == s.size() || s[i] == sep) {
            if (i > start) out.emplace_back(s.substr(start, i - start));
            start = i + 1;
        }
    }
    return out;
}

bool same_time_equal(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    unsigned diff = 0;
    for (std::size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
    return diff == 0;
}

}  // namespace

std::string PasswordTable::md5_hex(std::string_view text) { return server::md5_hex(text); }

void PasswordTable::add_user(std::string username, std::string_view password, std::vector<std::string> privileges) {
    (void)add_user_md5(std::move(username), md5_hex(password), std::move(privileges));
}

Result<void> PasswordTable::add_user_md5(std::string username, std::string_view md5_hex_text,
                                         std::vector<std::string> privileges) {
    std::string digest = lower(md5_hex_text);
    if (!is_md5_hex(digest)) return fail(MessageErrorType::InvalidArgument, "password hash is not 32 hex digits");
    for (auto& u : users_) {
        if (u.username == username) {
            u.password_md5 = std::move(digest);
            u.privileges = std::move(privileges);
            return {};
        }
    }
    users_.push_back(User{std::move(username), std::move(digest), std::move(privileges)});
    return {};
}

Result<PasswordTable> PasswordTable::parse(std::string_view text) {
    PasswordTable table;
    std::size_t line_no = 0;
    for (const auto& raw : split(text, '\n')) {
        ++line_no;
        std::string line = raw;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        std::vector<std::string> fields;
        for (auto& f : split(line, ' '))
            for (auto& g : split(f, '\t')) fields.push_back(std::move(g));
        if (fields.empty() || fields[0][0] == '#') continue;
        if (fields.size() < 3)
            return fail(MessageErrorType::InvalidArgument,
                        "password file line " + std::to_string(line_no) + ": expected username, hash, privileges");
        std::vector<std::string> privileges;
        if (fields[2] != "_") privileges = split(fields[2], ',');
        if (auto r = table.add_user_md5(fields[0], fields[1], std::move(privileges)); !r)
            return fail(MessageErrorType::InvalidArgument,
                        "password file line " + std::to_string(line_no) + ": " + r.error().message);
    }
    return table;
}

Result<PasswordTable> PasswordTable::load_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return fail(MessageErrorType::IOError, "cannot read password file " + path);
    std::ostringstream text;
    text << in.rdbuf();
    if (text.str().size() > kMaxFileBytes) return fail(MessageErrorType::InvalidArgument, "password file " + path + " is too large");
    auto t = parse(text.str());
    if (!t) return fail(MessageErrorType::InvalidArgument, path + ": " + t.error().message);
    return t;
}

Result<void> PasswordTable::check(std::string_view username, const MessageElement* credentials) const {
    const MessageElement* password = nullptr;
    if (credentials && credentials->type == DataTypes::dictionary_t) password = credentials->find("password");
    if (!password || password->type != DataTypes::string_t)
        return fail(MessageErrorType::AuthenticationError, "Password not supplied in credentials");
    const std::string digest = md5_hex(read_string(*password));
    bool ok = false;
    for (const auto& u : users_) ok |= (u.username == username) & same_time_equal(u.password_md5, digest);
    if (!ok) return fail(MessageErrorType::AuthenticationError, "Invalid username or password");
    return {};
}

}  // namespace rr::server

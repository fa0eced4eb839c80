// A username/password table for ObjectService authentication (wire.md §12).
//
// Passwords are kept as the lower-case hex MD5 of their UTF-8 text, the format of CORE's password files
// (`PasswordFileUserAuthenticator`): `<username> <md5-hex> <privileges> [<client NodeIDs>]`, one user per
// line. MD5 is what the official format uses, not a recommendation: credentials travel in clear inside
// the RR stream anyway, so use TLS where confidentiality matters. Plain passwords given to add_user()
// are hashed at once and never stored.
//
// A client logs in with `username` and `credentials` (a map{string} of varvalues whose `password` entry
// is a string). Failures: AuthenticationError "Invalid username or password" or "Password not supplied
// in credentials". Comparison of the hashes takes the same time whatever the input.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "base/error/rr_error.hpp"
#include "base/message/message.hpp"

namespace rr::server {

class PasswordTable {
public:
    struct User {
        std::string username;
        std::string password_md5;             ///< 32 lower-case hex digits
        std::vector<std::string> privileges;  ///< e.g. "objectlock"; empty for none
    };

    /// Adds (or replaces) a user from a plain password.
    void add_user(std::string username, std::string_view password, std::vector<std::string> privileges = {});
    /// Adds (or replaces) a user from an MD5 hex digest. Errors: InvalidArgument (not 32 hex digits).
    Result<void> add_user_md5(std::string username, std::string_view md5_hex, std::vector<std::string> privileges = {});
    /// Parses CORE's password file format (privileges `_` = none; the NodeID column is ignored; blank
    /// lines and lines starting with `#` are skipped). Errors: InvalidArgument naming the bad line.
    static Result<PasswordTable> parse(std::string_view text);
    /// parse() on the contents of the file at `path` (at most kMaxFileBytes). Errors: IOError (cannot
    /// read), InvalidArgument (too large, or parse errors, with the path).
    static Result<PasswordTable> load_file(const std::string& path);
    static constexpr std::size_t kMaxFileBytes = 4u * 1024u * 1024u;

    bool empty() const noexcept { return users_.empty(); }
    const std::vector<User>& users() const noexcept { return users_; }

    /// Checks a login. Errors: AuthenticationError.
    Result<void> check(std::string_view username, const MessageElement* credentials) const;

    /// Lower-case hex MD5 of `text`.
    static std::string md5_hex(std::string_view text);

private:
    std::vector<User> users_;
};

}  // namespace rr::server

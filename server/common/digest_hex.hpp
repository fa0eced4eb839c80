// Message digests as lower-case hex text (OpenSSL's EVP_Digest), for the password file's MD5
// (server/service/password_table) and the bearer-token file's SHA-256 (server/gateway/auth/token_auth).
#pragma once

#include <string>
#include <string_view>

namespace rr::server {

/// MD5 of `text`: 32 hex digits (the official password file's format; not a recommendation).
std::string md5_hex(std::string_view text);
/// SHA-256 of `text`: 64 hex digits.
std::string sha256_hex(std::string_view text);

}  // namespace rr::server

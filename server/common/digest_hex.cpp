#include "server/common/digest_hex.hpp"

#include <openssl/evp.h>

namespace rr::server {
namespace {

std::string digest_hex(std::string_view text, const EVP_MD* type) {
    unsigned char md[EVP_MAX_MD_SIZE];
    unsigned int n = 0;
    EVP_Digest(text.data(), text.size(), md, &n, type, nullptr);
    static constexpr char kHex[] = "0123456789abcdef";
    std::string out;
    out.reserve(2 * n);
    for (unsigned i = 0; i < n; ++i) {
        out += kHex[md[i] >> 4];
        out += kHex[md[i] & 15];
    }
    return out;
}

}  // namespace

std::string md5_hex(std::string_view text) { return digest_hex(text, EVP_md5()); }
std::string sha256_hex(std::string_view text) { return digest_hex(text, EVP_sha256()); }

}  // namespace rr::server

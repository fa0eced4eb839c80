#include "core/session/starttls.hpp"

#include <algorithm>

#include "base/message/error_entry.hpp"
#include "base/message/message_reader.hpp"
#include "base/message/message_writer.hpp"
#include "core/session/elements.hpp"

namespace rr {
namespace {

constexpr std::string_view kMutualAuth = "mutualauth";

Limits starttls_limits() {
    Limits l;
    l.max_message_size = kMaxStartTlsMessageBytes;
    l.max_entries = 4;
    l.max_elements = 16;
    l.max_nesting_depth = 1;
    return l;
}

// MessageSize from a complete preamble, or nullopt when it is not an RRAC preamble within the bound.
std::optional<std::size_t> preamble_size(std::span<const std::byte> preamble) {
    auto size = read_message_preamble(preamble, starttls_limits());
    if (!size) return std::nullopt;
    return *size;
}

bool says_true(const MessageElement* e) { return e && read_string(*e) == "true"; }

std::vector<std::byte> encode_or_empty(const Message& m) {
    std::vector<std::byte> out;
    if (!encode_message(m, out)) out.clear();
    return out;
}

}  // namespace

// --- client ----------------------------------------------------------------------------------------

StartTlsClient::StartTlsClient(StartTlsClientConfig config, MonoTime now)
    : config_(std::move(config)), deadline_(now + config_.timeout) {
    Message m;
    m.version = 2;
    m.header.receiver_node_id = config_.target_node_id;
    m.header.receiver_node_name = config_.target_node_name;
    MessageEntry e;
    e.entry_type = MessageEntryType::StreamOp;
    e.member_name = std::string(kStartTlsOp);
    if (config_.mutual_auth) e.elements.push_back(make_string_element(std::string(kMutualAuth), "true"));
    m.entries.push_back(std::move(e));
    request_ = encode_or_empty(m);
    if (request_.empty()) fail_with(make_error(MessageErrorType::InvalidArgument, "STARTTLS: cannot encode the request"));
}

std::size_t StartTlsClient::bytes_wanted() const noexcept {
    if (state_ != StartTlsState::waiting) return 0;
    if (reply_.size() < kMessagePreambleBytes) return kMessagePreambleBytes - reply_.size();
    return reply_size_ - reply_.size();
}

void StartTlsClient::feed(std::span<const std::byte> bytes, MonoTime now) {
    while (state_ == StartTlsState::waiting && !bytes.empty()) {
        const std::size_t n = std::min(bytes.size(), bytes_wanted());
        reply_.insert(reply_.end(), bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n));
        bytes = bytes.subspan(n);
        if (reply_.size() == kMessagePreambleBytes) {
            auto size = read_message_preamble(reply_, starttls_limits());
            if (!size) {
                fail_with(make_error(MessageErrorType::ProtocolError, "STARTTLS: bad reply (" + size.error().message + ")"));
                return;
            }
            reply_size_ = *size;
        } else if (reply_.size() > kMessagePreambleBytes && reply_.size() == reply_size_) {
            if (!bytes.empty()) {
                fail_with(make_error(MessageErrorType::ProtocolError, "STARTTLS: the server sent more than its reply"));
                return;
            }
            handle_reply();
        }
    }
}

void StartTlsClient::handle_reply() {
    const Limits limits = starttls_limits();
    auto decoded = decode_message(SharedBytes::copy_of(std::span<const std::byte>(reply_)), limits);
    if (!decoded) {
        fail_with(make_error(MessageErrorType::ProtocolError, "STARTTLS: bad reply (" + decoded.error().message + ")"));
        return;
    }
    const Message& m = *decoded;
    if (m.entries.size() != 1 || m.entries.front().entry_type != MessageEntryType::StreamOpRet ||
        m.entries.front().member_name != kStartTlsOp) {
        fail_with(make_error(MessageErrorType::ProtocolError, "STARTTLS: the reply is not a STARTTLS StreamOpRet"));
        return;
    }
    const MessageEntry& e = m.entries.front();
    if (auto err = entry_error(e)) {
        fail_with(std::move(*err));
        return;
    }
    // Which node answered (CORE StreamOpMessageReceived): any node when none was asked for; the
    // NodeID asked for; or, asked by NodeName only, the node of that name.
    const auto& h = m.header;
    if (config_.target_node_id.is_any() && config_.target_node_name.empty()) {
        result_.remote_node_id = h.sender_node_id;
    } else if (config_.target_node_id == h.sender_node_id) {
        result_.remote_node_id = config_.target_node_id;
    } else if (config_.target_node_id.is_any() && h.sender_node_name == config_.target_node_name) {
        result_.remote_node_id = h.sender_node_id;
    } else {
        fail_with(make_error(MessageErrorType::ConnectionError,
                             "Could not create TLS connection: the server answered as node " + h.sender_node_id.to_string() +
                                 (h.sender_node_name.empty() ? std::string() : " \"" + h.sender_node_name + "\"")));
        return;
    }
    result_.remote_node_name = h.sender_node_name;
    result_.mutual_auth = says_true(e.find(kMutualAuth));
    state_ = StartTlsState::done;
}

std::optional<MonoTime> StartTlsClient::next_deadline() const noexcept {
    if (state_ != StartTlsState::waiting) return std::nullopt;
    return deadline_;
}

void StartTlsClient::on_timer(MonoTime now) {
    if (state_ == StartTlsState::waiting && now >= deadline_)
        fail_with(make_error(MessageErrorType::ConnectionError, "STARTTLS timed out (no answer from the server)"));
}

void StartTlsClient::fail_with(RRError e) {
    state_ = StartTlsState::failed;
    error_ = std::move(e);
}

// --- server ----------------------------------------------------------------------------------------

StartTlsServer::StartTlsServer(StartTlsServerConfig config) : config_(std::move(config)) {}

std::size_t StartTlsServer::bytes_wanted() const noexcept {
    if (kind_ != FirstMessage::need_more) return 0;
    if (received_.size() < kMessagePreambleBytes) return kMessagePreambleBytes - received_.size();
    auto size = preamble_size(std::span<const std::byte>(received_).first(kMessagePreambleBytes));
    return size ? *size - std::min(*size, received_.size()) : 0;
}

void StartTlsServer::feed(std::span<const std::byte> bytes) {
    received_.insert(received_.end(), bytes.begin(), bytes.end());
    if (kind_ != FirstMessage::need_more) return;
    if (received_.size() < kMessagePreambleBytes) return;
    auto size = preamble_size(std::span<const std::byte>(received_).first(kMessagePreambleBytes));
    if (!size) {  // not RRAC, or too large for STARTTLS: the stream protocol's business
        kind_ = FirstMessage::plain;
        return;
    }
    if (received_.size() < *size) return;
    decide();
}

void StartTlsServer::decide() {
    auto size = preamble_size(std::span<const std::byte>(received_).first(kMessagePreambleBytes));
    auto decoded = decode_message(SharedBytes::copy_of(std::span<const std::byte>(received_).first(*size)), starttls_limits());
    if (!decoded || decoded->entries.size() != 1 || decoded->entries.front().entry_type != MessageEntryType::StreamOp ||
        decoded->entries.front().member_name != kStartTlsOp || received_.size() != *size) {
        // CreateConnection, anything else, or STARTTLS with bytes after it (a client must wait for the
        // reply): the ordinary stream protocol takes it from here.
        kind_ = FirstMessage::plain;
        return;
    }
    const Message& m = *decoded;
    const MessageEntry& e = m.entries.front();
    mutual_auth_ = says_true(e.find(kMutualAuth));

    Message reply;
    reply.version = 2;
    reply.header.sender_node_id = config_.local_node_id;
    reply.header.sender_node_name = config_.local_node_name;
    reply.header.receiver_node_id = m.header.sender_node_id;
    reply.header.receiver_node_name = m.header.sender_node_name;
    MessageEntry r;
    r.entry_type = MessageEntryType::StreamOpRet;
    r.member_name = std::string(kStartTlsOp);

    // The node matching of CORE: (any, ""), (mine, ""), (any, my name), (mine, my name).
    const auto& h = m.header;
    const bool id_ok = h.receiver_node_id.is_any() || h.receiver_node_id == config_.local_node_id;
    const bool name_ok = h.receiver_node_name.empty() || h.receiver_node_name == config_.local_node_name;
    if (!id_ok || !name_ok) {
        refusal_ = make_error(MessageErrorType::NodeNotFound, "Node not found");
        set_entry_error(r, refusal_);
        kind_ = FirstMessage::refused;
    } else if (!config_.certificate_loaded) {
        refusal_ = make_error(MessageErrorType::ConnectionError, "Server certificate not loaded");
        set_entry_error(r, refusal_);
        kind_ = FirstMessage::refused;
    } else {
        if (mutual_auth_ && config_.verifies_client_certificates) r.elements.push_back(make_string_element(std::string(kMutualAuth), "true"));
        kind_ = FirstMessage::start_tls;
    }
    reply.entries.push_back(std::move(r));
    reply_ = encode_or_empty(reply);
    if (reply_.empty()) kind_ = FirstMessage::plain;  // cannot happen with these fields; never half-answer
}

}  // namespace rr

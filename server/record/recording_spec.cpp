#include "server/record/recording_spec.hpp"

#include <algorithm>
#include <set>

#include "server/record/recording_format.hpp"

namespace rr::server::record {
namespace {

using nlohmann::json;

Result<std::uint64_t> unsigned_of(const json& j, const std::string& key) {
    if (j.is_number_unsigned()) return j.get<std::uint64_t>();
    if (j.is_number_integer() && j.get<std::int64_t>() >= 0) return static_cast<std::uint64_t>(j.get<std::int64_t>());
    return fail(MessageErrorType::InvalidArgument, "record: " + key + ": expected a non-negative integer");
}

Result<std::string> string_of(const json& j, const std::string& key) {
    if (!j.is_string()) return fail(MessageErrorType::InvalidArgument, "record: " + key + ": expected a string");
    return j.get<std::string>();
}

// `encoding`: a format's name or a list of them, kept in the formats' order, each once.
Result<std::vector<std::string>> encodings_of(const json& j) {
    const json given = j.is_array() ? j : json::array({j});
    std::vector<std::string> names, out;
    for (const auto& f : builtin_recording_formats())
        if (f->is_encoding()) names.emplace_back(f->name());
    for (const auto& x : given) {
        if (!x.is_string() || std::find(names.begin(), names.end(), x.get<std::string>()) == names.end()) {
            std::string expected;
            for (const auto& n : names) expected += json(n).dump() + ", ";
            expected.resize(expected.size() - 2);
            return fail(MessageErrorType::InvalidArgument, "record: encoding: expected " + expected + " or a list of " +
                                                               (names.size() == 2 ? "both" : "them") + ", not " + x.dump());
        }
    }
    for (const auto& n : names)
        if (std::find(given.begin(), given.end(), n) != given.end()) out.push_back(n);
    if (out.empty()) return fail(MessageErrorType::InvalidArgument, "record: encoding: empty list");
    return out;
}

}  // namespace

Result<RecordingSpec> spec_from_json(const json& j) {
    static const std::set<std::string> keys{"device",         "members",          "encoding",        "directory",
                                            "prefix",         "property_period_ms", "max_file_bytes",  "max_file_seconds",
                                            "max_total_bytes", "duration_s",       "queue_bytes",     "chunk_bytes",
                                            "compression",    "foxglove_images"};
    if (!j.is_object()) return fail(MessageErrorType::InvalidArgument, "record: expected an object");
    for (const auto& [k, v] : j.items())
        if (!keys.count(k)) {
            std::string list;
            for (const auto& x : keys) list += (list.empty() ? "" : ", ") + x;
            return fail(MessageErrorType::InvalidArgument, "record: " + k + ": unknown key (expected one of: " + list + ")");
        }
    RecordingSpec s;
    if (!j.contains("device")) return fail(MessageErrorType::InvalidArgument, "record: device: missing");
    auto device = string_of(j["device"], "device");
    if (!device) return device.take_error();
    s.device = *device;
    if (s.device.empty()) return fail(MessageErrorType::InvalidArgument, "record: device: empty");
    if (j.contains("members")) {
        if (!j["members"].is_array()) return fail(MessageErrorType::InvalidArgument, "record: members: expected a list of member names");
        for (const auto& m : j["members"]) {
            auto name = string_of(m, "members[]");
            if (!name) return name.take_error();
            s.members.push_back(*name);
        }
    }
    if (j.contains("encoding")) {
        auto encodings = encodings_of(j["encoding"]);
        if (!encodings) return encodings.take_error();
        s.encodings = std::move(*encodings);
    }
    if (j.contains("directory")) {
        auto d = string_of(j["directory"], "directory");
        if (!d) return d.take_error();
        if (auto r = check_subfolder(*d); !r) return r.take_error();
        s.directory = *d;
    }
    if (j.contains("prefix")) {
        auto p = string_of(j["prefix"], "prefix");
        if (!p) return p.take_error();
        if (auto r = check_prefix(*p); !r) return r.take_error();
        s.prefix = *p;
    }
    auto number = [&](const char* key, auto apply) -> Result<void> {
        if (!j.contains(key)) return {};
        auto v = unsigned_of(j[key], key);
        if (!v) return v.take_error();
        apply(*v);
        return {};
    };
    if (auto r = number("property_period_ms", [&](std::uint64_t v) { s.property_period = std::chrono::milliseconds(v); }); !r) return r.take_error();
    if (auto r = number("max_file_bytes", [&](std::uint64_t v) { s.max_file_bytes = v; }); !r) return r.take_error();
    if (auto r = number("max_file_seconds", [&](std::uint64_t v) { s.max_file_duration = std::chrono::seconds(v); }); !r) return r.take_error();
    if (auto r = number("max_total_bytes", [&](std::uint64_t v) { s.max_total_bytes = v; }); !r) return r.take_error();
    if (auto r = number("duration_s", [&](std::uint64_t v) { s.duration = std::chrono::seconds(v); }); !r) return r.take_error();
    if (auto r = number("queue_bytes", [&](std::uint64_t v) { s.queue_bytes = v; s.queue_bytes_given = true; }); !r) return r.take_error();
    if (auto r = number("chunk_bytes", [&](std::uint64_t v) { s.chunk_bytes = v; }); !r) return r.take_error();
    if (j.contains("compression")) {
        if (j["compression"] == "zstd") s.compress = true;
        else if (j["compression"] == "none") s.compress = false;
        else return fail(MessageErrorType::InvalidArgument, "record: compression: expected \"zstd\" or \"none\"");
    }
    if (j.contains("foxglove_images")) {
        if (!j["foxglove_images"].is_boolean())
            return fail(MessageErrorType::InvalidArgument, "record: foxglove_images: expected true or false");
        s.foxglove_images = j["foxglove_images"].get<bool>();
    }
    if (s.chunk_bytes < 1024 || s.chunk_bytes > (64u << 20))
        return fail(MessageErrorType::InvalidArgument, "record: chunk_bytes: between 1024 and 67108864");
    if (s.queue_bytes < 4096) return fail(MessageErrorType::InvalidArgument, "record: queue_bytes: at least 4096");
    if (s.max_total_bytes && s.max_file_bytes && s.max_total_bytes < s.max_file_bytes)
        return fail(MessageErrorType::InvalidArgument, "record: max_total_bytes: smaller than max_file_bytes");
    return s;
}

namespace {

bool name_char(char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_' || c == '.';
}

// JSON text of a value, so a NUL or a control character is visible in a message.
std::string shown(std::string_view v) { return json(std::string(v)).dump(-1, ' ', true, json::error_handler_t::replace); }

// What is wrong with one name (a prefix, or a part of a directory); "" when nothing.
std::string name_problem(std::string_view name) {
    if (name.empty()) return "an empty part";
    if (name.size() > 64) return "a part of " + std::to_string(name.size()) + " characters (at most 64)";
    if (name.front() == '.') return "a part starting with a dot (" + shown(name) + ": no \".\", \"..\" or hidden names)";
    for (char c : name)
        if (!name_char(c)) return "the character " + shown(std::string(1, c)) + " (letters, digits, '-', '_' and '.' only)";
    return {};
}

}  // namespace

std::string default_recordings_root(const char* state_directory) {
    if (state_directory && *state_directory) {
        std::string_view dirs(state_directory);
        const std::string first(dirs.substr(0, dirs.find(':')));
        if (!first.empty()) return first + (first.back() == '/' ? "" : "/") + "recordings";
    }
    return "recordings";
}

Result<void> check_subfolder(std::string_view d) {
    if (d.empty()) return {};
    if (d.front() == '/')
        return fail(MessageErrorType::InvalidArgument, "record: directory: " + shown(d) +
                                                           " is an absolute path; name a sub-folder of the recordings root (e.g. \"lab/run1\")");
    if (d.size() > 255) return fail(MessageErrorType::InvalidArgument, "record: directory: longer than 255 characters");
    std::size_t parts = 0;
    for (std::size_t pos = 0;;) {
        const auto slash = d.find('/', pos);
        const auto part = d.substr(pos, slash == std::string_view::npos ? std::string_view::npos : slash - pos);
        if (auto p = name_problem(part); !p.empty())
            return fail(MessageErrorType::InvalidArgument,
                        "record: directory: " + shown(d) + " has " + p + "; name a sub-folder of the recordings root");
        if (++parts > 8) return fail(MessageErrorType::InvalidArgument, "record: directory: more than 8 levels of folders");
        if (slash == std::string_view::npos) break;
        pos = slash + 1;
    }
    return {};
}

Result<void> check_prefix(std::string_view p) {
    if (p.empty()) return {};
    if (auto problem = name_problem(p); !problem.empty())
        return fail(MessageErrorType::InvalidArgument, "record: prefix: " + shown(p) + " has " + problem);
    return {};
}

Result<void> check_spec_bounds(const RecordingSpec& spec, const RecordingsSettings& settings) {
    if (spec.queue_bytes_given && spec.queue_bytes > settings.max_queue_bytes)
        return fail(MessageErrorType::InvalidArgument, "record: queue_bytes: " + std::to_string(spec.queue_bytes) +
                                                           " is over the gateway's limit of " + std::to_string(settings.max_queue_bytes) +
                                                           " (recordings.max_queue_bytes)");
    return {};
}

json spec_json(const RecordingSpec& s) {
    return json{{"device", s.device},
                {"members", s.members},
                {"encoding", s.encodings},
                {"directory", s.directory},
                {"prefix", s.prefix},
                {"property_period_ms", s.property_period.count()},
                {"max_file_bytes", s.max_file_bytes},
                {"max_file_seconds", s.max_file_duration.count()},
                {"max_total_bytes", s.max_total_bytes},
                {"duration_s", s.duration.count()},
                {"queue_bytes", s.queue_bytes},
                {"chunk_bytes", s.chunk_bytes},
                {"compression", s.compress ? "zstd" : "none"},
                {"foxglove_images", s.foxglove_images}};
}

}  // namespace rr::server::record

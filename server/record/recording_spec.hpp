// What one recording records and where (docs/recording.md "Configuration"): from a `record:` entry of
// the gateway configuration or from POST /api/recordings.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/error/rr_error.hpp"

namespace rr::server::record {

struct RecordingSpec {
    std::string device;                ///< gateway device name
    /// Root-object members to record: wires, pipes, events and properties. Empty: every wire, pipe and
    /// event (and every readable property when `property_period` is set).
    std::vector<std::string> members;
    /// The formats written, by name (`encoding`; recording_format.hpp, the built-in ones registered in
    /// formats/formats.cpp): `json` channels (JSON mapping + JSON Schema) and `robotraconteur` channels
    /// (RR entry bytes, for replay) by default. In the order of the formats' registration, each once.
    std::vector<std::string> encodings{"json", "robotraconteur"};
    /// With `json`: a standard image member (com.robotraconteur.image.Image / CompressedImage) also on a
    /// channel `<device>/<member>/foxglove` as foxglove.RawImage / CompressedImage
    /// (formats/foxglove_image_format.hpp).
    bool foxglove_images = true;
    /// The sub-folder of the recordings root the files go to ("" = the root itself): relative, parts of
    /// letters, digits and `-_.` without a leading dot, joined by `/` (check_subfolder). For `rr record`,
    /// which writes on its user's own computer, the folder itself (the CLI's root).
    std::string directory;
    /// File name prefix ("" = the device name, its other characters made `_`): files are
    /// <root>/<directory>/<prefix>-<UTC time>-<n>.mcap. Letters, digits and `-_.`, no leading dot,
    /// at most 64 characters (check_prefix).
    std::string prefix;
    /// Properties polled at this period (0 = properties are not recorded unless named; a named property
    /// without a period is polled every second).
    std::chrono::milliseconds property_period{0};
    /// A new file after this many bytes / this long (0 = never).
    std::uint64_t max_file_bytes = 256ull << 20;
    std::chrono::seconds max_file_duration{0};
    /// Disk budget of this recording's files: the oldest files go when a new file would exceed it
    /// (0 = unbounded).
    std::uint64_t max_total_bytes = 0;
    /// The recording stops by itself after this long (0 = until stopped).
    std::chrono::seconds duration{0};
    /// Entries waiting for the writer thread, bytes (over it: dropped and counted).
    std::size_t queue_bytes = 64u << 20;
    /// queue_bytes was asked for (a JSON key). The default is lowered to recordings.max_queue_bytes
    /// when that is smaller; a value asked for over it is refused (check_spec_bounds).
    bool queue_bytes_given = false;
    /// Uncompressed chunk size (a killed gateway loses at most the chunk being filled).
    std::size_t chunk_bytes = 1u << 20;
    bool compress = true;              ///< zstd chunks
    /// A new file once the writer keeps this much more for the open file's summary than its schemas and
    /// channels (its chunk indexes grow by one per chunk: mcap::McapWriter::summary_memory_bytes). Not a
    /// JSON key: tests lower it.
    std::size_t max_index_bytes = 8u << 20;

    /// Whether `encoding` names the format `name`.
    bool encodes(std::string_view name) const noexcept {
        for (const auto& e : encodings)
            if (e == name) return true;
        return false;
    }
};

/// `recordings:` of the gateway configuration (docs/gateway-config.md, docs/recording.md "Where
/// recordings go"): where every recording of the gateway writes, and the bounds on them.
struct RecordingsSettings {
    /// The folder every recording writes below. "" = the default, resolved when the gateway starts
    /// (default_recordings_root): `$STATE_DIRECTORY/recordings` when systemd gives the gateway a state
    /// directory (the Debian package's unit), else `recordings` in the working directory (the container's
    /// is its state directory, /var/lib/rr-gateway).
    std::string root;
    /// Every file below the root together, bytes. A recording that would pass it is refused (507) when
    /// it starts, or ends `failed` when the root fills up while it writes.
    std::uint64_t max_total_bytes = 2ull << 30;
    /// Recordings running (or starting) at once; one more is refused with 429.
    std::size_t max_active = 8;
    /// The largest `queue_bytes` a recording may ask for; more is refused with 400.
    std::size_t max_queue_bytes = 256u << 20;
    /// Statuses of ended (stopped or failed) recordings kept for GET /api/recordings; the oldest go first.
    std::size_t keep_ended = 64;
    /// The memory one replayed device's MCAP reader may hold at once (mcap::ReaderLimits::max_memory_bytes).
    std::uint64_t replay_memory_bytes = 256ull << 20;
};

/// The root when RecordingsSettings::root is "": `$STATE_DIRECTORY/recordings` when the variable is set
/// (systemd's StateDirectory=; the first of a colon-separated list), else "recordings" (relative: the
/// working directory). `state_directory` is the variable's value (nullptr: unset).
std::string default_recordings_root(const char* state_directory);

/// A `directory`: "" or relative parts of 1..64 letters, digits and `-_.`, no part starting with a dot
/// (so no `.` or `..`), at most 8 parts and 255 characters. Errors: InvalidArgument saying what is wrong
/// ("record: directory: \"/tmp\" is an absolute path; name a sub-folder of the recordings root").
Result<void> check_subfolder(std::string_view directory);
/// A `prefix`: "" or 1..64 letters, digits and `-_.`, not starting with a dot. Errors: InvalidArgument.
Result<void> check_prefix(std::string_view prefix);
/// The bounds of `settings` a spec must keep: queue_bytes, when asked for, at most max_queue_bytes.
/// Errors: InvalidArgument naming the key and the bound.
Result<void> check_spec_bounds(const RecordingSpec& spec, const RecordingsSettings& settings);

/// The spec from JSON (POST /api/recordings, docs/recording.md), the same keys as a `record:` entry:
/// {"device", "members"?, "encoding"?: a format's name or a list of them ("json", "robotraconteur";
/// builtin_recording_formats), "directory"?,
/// "prefix"?, "property_period_ms"?, "max_file_bytes"?, "max_file_seconds"?, "max_total_bytes"?,
/// "duration_s"?, "queue_bytes"?, "chunk_bytes"?, "compression"?: "zstd"|"none", "foxglove_images"?: bool}.
/// `directory` and `prefix` are checked by check_subfolder and check_prefix.
/// Errors: InvalidArgument naming the key (unknown keys included).
Result<RecordingSpec> spec_from_json(const nlohmann::json& j);
/// The spec as JSON (the same keys).
nlohmann::json spec_json(const RecordingSpec& spec);

}  // namespace rr::server::record

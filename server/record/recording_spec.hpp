// What one recording records and where (docs/recording.md "Configuration"): from a `record:` entry of
// the gateway configuration or from POST /api/recordings.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error/rr_error.hpp"

namespace rr::server::record {

struct RecordingSpec {
    std::string device;                ///< gateway device name
    /// Root-object members to record: wires, pipes, events and properties. Empty: every wire, pipe and
    /// event (and every readable property when `property_period` is set).
    std::vector<std::string> members;
    bool json = true;                  ///< `json` channels (JSON mapping + JSON Schema)
    bool robotraconteur = true;        ///< `robotraconteur` channels (RR entry bytes, for replay)
    /// With `json`: a standard image member (com.robotraconteur.image.Image / CompressedImage) also on a
    /// channel `<device>/<member>/foxglove` as foxglove.RawImage / CompressedImage (foxglove_image.hpp).
    bool foxglove_images = true;
    std::string directory = "recordings";
    /// File name prefix ("" = the device name): files are <directory>/<prefix>-<UTC time>-<n>.mcap.
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
    /// Uncompressed chunk size (a killed gateway loses at most the chunk being filled).
    std::size_t chunk_bytes = 1u << 20;
    bool compress = true;              ///< zstd chunks
};

/// The spec from JSON (POST /api/recordings, docs/recording.md), the same keys as a `record:` entry:
/// {"device", "members"?, "encoding"?: "json"|"robotraconteur"|["json","robotraconteur"], "directory"?,
/// "prefix"?, "property_period_ms"?, "max_file_bytes"?, "max_file_seconds"?, "max_total_bytes"?,
/// "duration_s"?, "queue_bytes"?, "chunk_bytes"?, "compression"?: "zstd"|"none", "foxglove_images"?: bool}.
/// Errors: InvalidArgument naming the key (unknown keys included).
Result<RecordingSpec> spec_from_json(const nlohmann::json& j);
/// The spec as JSON (the same keys).
nlohmann::json spec_json(const RecordingSpec& spec);

}  // namespace rr::server::record

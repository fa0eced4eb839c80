// Replay reads a `robotraconteur` channel only when its `entry_format` is one it knows
// (channel_metadata.hpp kEntryFormat): a channel without it, or with another one, is refused at open
// with an error naming the channel; a known one opens.
#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <unistd.h>

#include "core/mcap/mcap_writer.hpp"
#include "server/mcap/mcap_file.hpp"
#include "server/record/channel_metadata.hpp"
#include "server/record/replay_device.hpp"
#include "test/support/temp_dir.hpp"

namespace fs = std::filesystem;
using namespace rr::server::record;

namespace {

constexpr std::string_view kThingDefinition = "service experimental.fmt\n\nobject Thing\n    wire double value [readonly]\nend\n";

std::span<const std::byte> text_bytes(std::string_view s) { return {reinterpret_cast<const std::byte*>(s.data()), s.size()}; }

// A one-channel recording of Thing.value whose channel has `entry_format` (none when nullopt).
fs::path recording_with_entry_format(const fs::path& dir, std::optional<std::string> entry_format) {
    const auto path = dir / ("thing-" + entry_format.value_or("none") + ".mcap");
    auto sink = rr::mcap::FileSink::create(path.string());
    REQUIRE(sink);
    rr::mcap::McapWriter writer(**sink);
    REQUIRE(writer.open());
    auto schema = writer.add_schema("experimental.fmt", kServiceDefinitionSchemaEncoding, text_bytes(kThingDefinition));
    REQUIRE(schema);
    ChannelMetadata metadata{{channel_key::device, "thing"},     {channel_key::member, "value"},
                             {channel_key::kind, "wire"},        {channel_key::object_type, "experimental.fmt.Thing"},
                             {channel_key::path, ""},            {channel_key::root_type, "experimental.fmt.Thing"},
                             {channel_key::type, "double"}};
    if (entry_format) metadata[channel_key::entry_format] = *entry_format;
    REQUIRE(writer.add_channel(*schema, "thing/value", kRobotRaconteurEncoding, metadata));
    REQUIRE(writer.close());
    return path;
}

}  // namespace

TEST_CASE("replay: a robotraconteur channel's entry_format is checked before anything is played") {
    rr::testing::TempDir dir("rr-replay-format");
    ReplayOptions known;
    known.file = recording_with_entry_format(dir.path, std::string(kEntryFormat)).string();
    auto opened = ReplayDevice::open(known);
    INFO((opened ? std::string() : opened.error().message));
    CHECK(opened);

    ReplayOptions other;
    other.file = recording_with_entry_format(dir.path, std::string("5")).string();
    auto refused = ReplayDevice::open(other);
    REQUIRE_FALSE(refused);
    CHECK(refused.error().type == rr::MessageErrorType::InvalidArgument);
    CHECK(refused.error().message.find("channel thing/value: entry_format \"5\" is not one this gateway reads (\"4\": RR message format 4)") !=
          std::string::npos);

    ReplayOptions missing;
    missing.file = recording_with_entry_format(dir.path, std::nullopt).string();
    auto without = ReplayDevice::open(missing);
    REQUIRE_FALSE(without);
    CHECK(without.error().type == rr::MessageErrorType::InvalidArgument);
    CHECK(without.error().message.find("channel thing/value: no entry_format") != std::string::npos);
}

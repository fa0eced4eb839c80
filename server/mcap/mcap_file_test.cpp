#include <catch2/catch.hpp>

#include <filesystem>
#include <unistd.h>

#include "core/mcap/mcap_reader.hpp"
#include "core/mcap/mcap_writer.hpp"
#include "server/mcap/mcap_file.hpp"

using namespace rr;
using namespace rr::mcap;

TEST_CASE("mcap: a recording written to a file reads back from the file, also before close") {
    auto dir = std::filesystem::temp_directory_path() / ("rr_mcap_file_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    auto path = (dir / "rec.mcap").string();
    auto sink = FileSink::create(path, true);
    REQUIRE(sink);
    McapWriter w(**sink);
    REQUIRE(w.open());
    auto ch = w.add_channel(0, "dev/m", "json");
    REQUIRE(ch);
    std::string text = "{\"x\":1}";
    std::span<const std::byte> data(reinterpret_cast<const std::byte*>(text.data()), text.size());
    REQUIRE(w.write({*ch, 1, 10, 10, data}));
    REQUIRE(w.flush());
    {
        // What a crash here would leave: the flushed chunk, readable.
        auto source = FileSource::open(path);
        REQUIRE(source);
        auto reader = McapReader::open(**source);
        REQUIRE(reader);
        CHECK(reader->truncated());
        auto m = reader->messages().next();
        REQUIRE(m);
        REQUIRE(*m);
        CHECK((*m)->data == std::vector<std::byte>(data.begin(), data.end()));
    }
    REQUIRE(w.close());
    REQUIRE((*sink)->close());
    auto source = FileSource::open(path);
    REQUIRE(source);
    auto reader = McapReader::open(**source);
    REQUIRE(reader);
    CHECK(reader->indexed());
    CHECK(reader->summary().statistics.message_count == 1);

    auto missing = FileSource::open((dir / "nope.mcap").string());
    REQUIRE_FALSE(missing);
    CHECK(missing.error().type == MessageErrorType::IOError);
    CHECK_THAT(missing.error().message, Catch::Contains("No such file or directory"));
    std::filesystem::remove_all(dir);
}

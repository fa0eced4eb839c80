// RecordingsRoot (recordings_root.hpp): sub-folders made part by part without following links, files
// made new (O_EXCL|O_NOFOLLOW, 0640), removals by name in the folder, and the root's disk budget.
#include <catch2/catch.hpp>

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "server/record/recordings_root.hpp"
#include "test/support/temp_dir.hpp"

using rr::MessageErrorType;
using rr::server::record::RecordingsRoot;
namespace fs = std::filesystem;

namespace {

struct TempDir : rr::testing::TempDir {
    TempDir() : rr::testing::TempDir("rr-root-test") {}
};

void write_file(const fs::path& p, const std::string& text) {
    std::ofstream f(p, std::ios::binary);
    f << text;
}

std::string read_file(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
}

}  // namespace

TEST_CASE("recordings root: sub-folders are made below the root, files new and 0640") {
    TempDir tmp;
    auto root = std::make_shared<RecordingsRoot>((tmp.path / "rec").string(), 0);
    CHECK(root->path() == (tmp.path / "rec").string());
    auto folder = root->open_folder("lab/run1");
    INFO((folder ? std::string() : folder.error().message));
    REQUIRE(folder);
    CHECK((*folder)->path() == (tmp.path / "rec/lab/run1").string());
    CHECK(fs::is_directory(tmp.path / "rec/lab/run1"));
    auto sink = (*folder)->create_file("a.mcap");
    REQUIRE(sink);
    const std::byte b[3] = {std::byte{1}, std::byte{2}, std::byte{3}};
    REQUIRE((*sink)->write(b));
    REQUIRE((*sink)->close());
    struct stat st {};
    REQUIRE(::stat((tmp.path / "rec/lab/run1/a.mcap").c_str(), &st) == 0);
    CHECK((st.st_mode & 0137) == 0);  // no group write, nothing for others, no execute
    CHECK(st.st_size == 3);
    REQUIRE(::stat((tmp.path / "rec/lab").c_str(), &st) == 0);
    CHECK((st.st_mode & 0027) == 0);

    // A taken name is never opened again (O_EXCL): the caller hears it was taken.
    bool exists = false;
    auto again = (*folder)->create_file("a.mcap", &exists);
    REQUIRE_FALSE(again);
    CHECK(exists);
    CHECK(fs::file_size(tmp.path / "rec/lab/run1/a.mcap") == 3);
    CHECK((*folder)->remove_file("a.mcap"));
    CHECK_FALSE(fs::exists(tmp.path / "rec/lab/run1/a.mcap"));

    // Names that are not a sub-folder are refused before anything is made.
    for (const char* bad : {"/tmp", "..", "a/../..", "a//b", ".hidden"}) {
        auto r = root->open_folder(bad);
        INFO(bad);
        REQUIRE_FALSE(r);
        CHECK(r.error().type == MessageErrorType::InvalidArgument);
    }
    CHECK_FALSE((*folder)->create_file("../x.mcap"));
    CHECK_FALSE(fs::exists(tmp.path / "rec/lab/x.mcap"));
}

TEST_CASE("recordings root: a symbolic link planted below the root is not followed") {
    TempDir tmp;
    fs::create_directories(tmp.path / "rec/lab");
    fs::create_directories(tmp.path / "outside");
    write_file(tmp.path / "outside/victim.txt", "precious");
    auto root = std::make_shared<RecordingsRoot>((tmp.path / "rec").string(), 0);

    // A folder link, at the end of the path or on the way.
    fs::create_directory_symlink(tmp.path / "outside", tmp.path / "rec/link");
    fs::create_directory_symlink(tmp.path / "outside", tmp.path / "rec/lab/deeper");
    for (const char* sub : {"link", "link/x", "lab/deeper"}) {
        auto f = root->open_folder(sub);
        INFO(sub);
        REQUIRE_FALSE(f);
        CHECK(f.error().type == MessageErrorType::IOError);
        CHECK_THAT(f.error().message, Catch::Contains("is a symbolic link (links below the recordings root are not followed)"));
    }
    CHECK_FALSE(fs::exists(tmp.path / "outside/x"));

    // A file link where a recording's file would go: the name counts as taken, the target is untouched.
    fs::create_symlink(tmp.path / "outside/victim.txt", tmp.path / "rec/lab/cam-1.mcap");
    auto lab = root->open_folder("lab");
    REQUIRE(lab);
    bool exists = false;
    auto sink = (*lab)->create_file("cam-1.mcap", &exists);
    REQUIRE_FALSE(sink);
    CHECK(exists);
    CHECK(read_file(tmp.path / "outside/victim.txt") == "precious");
    // Removing by that name removes the link, not its target.
    CHECK((*lab)->remove_file("cam-1.mcap"));
    CHECK(read_file(tmp.path / "outside/victim.txt") == "precious");

    // A file where a folder is wanted.
    write_file(tmp.path / "rec/plain", "x");
    auto plain = root->open_folder("plain/sub");
    REQUIRE_FALSE(plain);
    CHECK_THAT(plain.error().message, Catch::Contains((tmp.path / "rec/plain").string() + " is not a folder"));
}

TEST_CASE("recordings root: the budget counts the files below the root and what recordings set aside") {
    TempDir tmp;
    fs::create_directories(tmp.path / "rec/old");
    write_file(tmp.path / "rec/old/a.mcap", std::string(300000, 'a'));
    // A link to a big file outside is not counted (nor followed).
    write_file(tmp.path / "big", std::string(2000000, 'b'));
    fs::create_symlink(tmp.path / "big", tmp.path / "rec/old/big-link");
    CHECK(RecordingsRoot::bytes_below((tmp.path / "rec").string()) == 300000);
    CHECK(RecordingsRoot::bytes_below((tmp.path / "nothing").string()) == 0);

    auto root = std::make_shared<RecordingsRoot>((tmp.path / "rec").string(), 1000000);
    // 300,000 used: a recording setting aside 800,000 would pass 1,000,000.
    auto refused = root->admit(800000, 1 << 20);
    REQUIRE_FALSE(refused);
    CHECK(refused.error().type == MessageErrorType::OutOfSystemResource);
    CHECK_THAT(refused.error().message, Catch::Contains("300000 bytes used, 0 set aside by running recordings, this one needs 800000"));
    auto a = root->admit(500000, 0);
    REQUIRE(a);
    CHECK(root->used_bytes() == 300000);
    // The next one finds 500,000 set aside.
    auto b = root->admit(300000, 0);
    REQUIRE_FALSE(b);
    CHECK_THAT(b.error().message, Catch::Contains("500000 set aside"));
    // One without a budget of its own needs `at_least` now, then fails when the root fills.
    auto c = root->admit(0, 100000);
    REQUIRE(c);
    CHECK((*a)->note(400000));  // within its own share
    CHECK((*c)->note(100000));
    CHECK(root->used_bytes() == 800000);
    CHECK_FALSE((*c)->note(150000));  // 950,000 used + 100,000 still set aside for `a`
    CHECK((*c)->note(-150000));
    // A finished recording gives its share back; its files stay counted.
    a->reset();
    CHECK(root->used_bytes() == 800000);
    CHECK((*c)->note(150000));

    // Without a budget (rr record on its user's own computer) everything is admitted.
    auto unbounded = std::make_shared<RecordingsRoot>((tmp.path / "rec").string(), 0);
    CHECK(unbounded->admit(1ull << 50, 0));
}

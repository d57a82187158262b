// the INI dialect: sections, comments, includes, and line-accurate errors
#include "sim/runner/ini.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "sim/runner/files.h"

namespace paddock::runner {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// a scratch folder of small files for one test
class IniFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("paddock_ini_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                                        "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "sub");
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p.string();
  }
  // the message of the UserError that reading `path` throws
  std::string error_of(const std::string& path) {
    try {
      read_ini_file(path);
    } catch (const UserError& e) {
      return e.what();
    }
    return "(no error)";
  }
  fs::path dir_;
};

TEST(Ini, SectionsKeysAndComments) {
  const auto e = parse_ini_text(
      "; a comment\n"
      "# another\n"
      "[a]\n"
      "x = 1   ; trailing\n"
      "  y=two words # trailing too\n"
      "\n"
      "[b]\n"
      "url = http://x;y\n",
      "t.ini", ".");
  ASSERT_EQ(e.size(), 3u);
  EXPECT_EQ(e[0].section, "a");
  EXPECT_EQ(e[0].key, "x");
  EXPECT_EQ(e[0].value, "1");
  EXPECT_EQ(e[0].line, 4);
  EXPECT_EQ(e[1].value, "two words");
  EXPECT_EQ(e[1].line, 5);
  // a ';' not after whitespace is part of the value
  EXPECT_EQ(e[2].value, "http://x;y");
  EXPECT_EQ(e[2].where(), "t.ini:8");
}

TEST(Ini, SyntaxErrorsNameFileAndLine) {
  auto msg = [](const std::string& text) {
    try {
      parse_ini_text(text, "bad.ini", ".");
    } catch (const UserError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_THAT(msg("[a]\nx = 1\nnot a pair\n"), HasSubstr("bad.ini:3: expected 'key = value'"));
  EXPECT_THAT(msg("[a\n"), HasSubstr("bad.ini:1: malformed section header"));
  EXPECT_THAT(msg("x = 1\n"), HasSubstr("bad.ini:1: key 'x' is outside any [section]"));
  EXPECT_THAT(msg("[a]\nx = 1\nx = 2\n"), HasSubstr("bad.ini:3: [a] x is already set at line 2"));
  EXPECT_THAT(msg("[a]\nbad key = 1\n"), HasSubstr("bad.ini:2: bad key 'bad key'"));
}

TEST_F(IniFiles, IncludeIsRelativeToTheIncludingFileAndLaterEntriesWin) {
  write("sub/vehicle.ini", "[v]\nmass = 190\nlf = 0.7\n");
  const auto top = write("top.ini", "include = sub/vehicle.ini\n[v]\nmass = 200\n");
  const auto e = read_ini_file(top);
  ASSERT_EQ(e.size(), 3u);
  EXPECT_EQ(e[0].file, (dir_ / "sub/vehicle.ini").string());
  EXPECT_EQ(e[0].line, 2);
  EXPECT_EQ(e[2].value, "200");
  EXPECT_EQ(e[2].line, 3);
}

// a file named bare, in the current folder (paddock run my.ini from where it
// lies): its includes and theirs are read from there
TEST_F(IniFiles, AFileInTheCurrentFolderIncludesRelativeToIt) {
  write("sub/vehicle.ini", "[v]\nmass = 190\n");
  write("mid.ini", "include = sub/vehicle.ini\n[v]\nlf = 0.7\n");
  write("top.ini", "include = mid.ini\n[v]\nmass = 200\n");
  const fs::path before = fs::current_path();
  fs::current_path(dir_);
  std::vector<IniEntry> e;
  std::string error;
  try {
    e = read_ini_file("top.ini");
  } catch (const UserError& x) {
    error = x.what();
  }
  fs::current_path(before);
  ASSERT_EQ(error, "");
  ASSERT_EQ(e.size(), 3u);
  EXPECT_EQ(e[0].value, "190");
  EXPECT_EQ(e[0].file, "sub/vehicle.ini");
  EXPECT_EQ(e[1].file, "mid.ini");
  EXPECT_EQ(e[2].value, "200");
}

TEST_F(IniFiles, IncludeInsideASectionReturnsToThatSection) {
  write("sub/part.ini", "[other]\nk = 1\n");
  const auto top = write("top.ini", "[mine]\ninclude = sub/part.ini\nafter = 2\n");
  const auto e = read_ini_file(top);
  ASSERT_EQ(e.size(), 2u);
  EXPECT_EQ(e[1].section, "mine");
}

TEST_F(IniFiles, IncludeCycleIsAnError) {
  write("a.ini", "include = b.ini\n");
  write("b.ini", "[s]\nk = 1\ninclude = a.ini\n");
  EXPECT_THAT(error_of((dir_ / "a.ini").string()), HasSubstr("b.ini:3: include cycle"));
}

TEST_F(IniFiles, MissingIncludeNamesTheIncludingLine) {
  const auto top = write("top.ini", "; x\ninclude = nowhere.ini\n");
  EXPECT_THAT(error_of(top), HasSubstr("top.ini:2: cannot include"));
  EXPECT_THAT(error_of(top), HasSubstr("nowhere.ini"));
}

TEST_F(IniFiles, MissingFileIsAnError) {
  EXPECT_THAT(error_of((dir_ / "none.ini").string()), HasSubstr("none.ini: cannot open"));
}

}  // namespace
}  // namespace paddock::runner

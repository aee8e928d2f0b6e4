// The program cache's file store (host/cl/program_cache.h): an entry reads back exactly as
// written, and anything else in its place (truncated, altered, written for another key, empty) is
// a miss, never an error.
#include "cl/program_cache.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

using namespace canopy;
namespace fs = std::filesystem;

namespace {

class ProgramCacheTest : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("canopy-test-cache-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string read(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }
  void write(const fs::path& p, const std::string& bytes) {
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out << bytes;
  }

  fs::path dir_;
  const std::string key_ = "device x\noptions -DA=1\nsource 0123\n";
  const std::vector<unsigned char> binary_ = {1, 2, 3, 0, 255, 7, 7, 7, 42};
};

TEST_F(ProgramCacheTest, EntryReadsBackAsWritten) {
  ProgramCache cache(dir_);
  EXPECT_FALSE(cache.load(key_));
  ASSERT_TRUE(cache.store(key_, binary_));
  auto got = cache.load(key_);
  ASSERT_TRUE(got);
  EXPECT_EQ(*got, binary_);
  // Only the entry: no temporary file is left behind.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

TEST_F(ProgramCacheTest, EveryTruncationIsAMiss) {
  ProgramCache cache(dir_);
  ASSERT_TRUE(cache.store(key_, binary_));
  const fs::path p = cache.entry_path(key_);
  const std::string whole = read(p);
  for (size_t n = 0; n < whole.size(); ++n) {
    write(p, whole.substr(0, n));
    EXPECT_FALSE(cache.load(key_)) << "truncated to " << n << " bytes";
  }
  write(p, whole + "x");
  EXPECT_FALSE(cache.load(key_)) << "a byte appended";
}

TEST_F(ProgramCacheTest, EveryFlippedByteIsAMiss) {
  ProgramCache cache(dir_);
  ASSERT_TRUE(cache.store(key_, binary_));
  const fs::path p = cache.entry_path(key_);
  const std::string whole = read(p);
  for (size_t i = 0; i < whole.size(); ++i) {
    std::string bad = whole;
    bad[i] = char(bad[i] ^ 0x10);
    write(p, bad);
    EXPECT_FALSE(cache.load(key_)) << "byte " << i << " flipped";
  }
}

TEST_F(ProgramCacheTest, AnEntryOfAnotherKeyIsAMiss) {
  ProgramCache cache(dir_);
  const std::string other = key_ + "headers 1\n";
  ASSERT_TRUE(cache.store(other, binary_));
  // Even under this key's name (a digest collision): the stored key is compared.
  fs::rename(cache.entry_path(other), cache.entry_path(key_));
  EXPECT_FALSE(cache.load(key_));
}

TEST_F(ProgramCacheTest, EntryNamesDependOnEveryPartOfTheKey) {
  ProgramCache cache(dir_);
  EXPECT_NE(cache.entry_path(key_), cache.entry_path(key_ + " "));
  EXPECT_NE(cache.entry_path("options -DA=1"), cache.entry_path("options -DA=2"));
  EXPECT_EQ(cache.entry_path(key_), cache.entry_path(std::string(key_)));
}

TEST_F(ProgramCacheTest, LeastRecentlyUsedEntriesAreRemoved) {
  ProgramCache cache(dir_);
  cache.max_entries = 3;
  const auto t0 = fs::file_time_type::clock::now() - std::chrono::hours(1);
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(cache.store(key_ + std::to_string(i), binary_));
    fs::last_write_time(cache.entry_path(key_ + std::to_string(i)), t0 + std::chrono::minutes(i));
  }
  ASSERT_TRUE(cache.load(key_ + "0")); // now the most recently used
  ASSERT_TRUE(cache.store(key_ + "3", binary_));
  EXPECT_TRUE(cache.load(key_ + "0"));
  EXPECT_FALSE(cache.load(key_ + "1")) << "the least recently used";
  EXPECT_TRUE(cache.load(key_ + "2"));
  EXPECT_TRUE(cache.load(key_ + "3"));
}

TEST_F(ProgramCacheTest, UnwritableDirectoryIsNotAnError) {
  write(dir_.string() + "-file", "x"); // a file where the directory would be
  ProgramCache cache(dir_.string() + "-file");
  EXPECT_FALSE(cache.store(key_, binary_));
  EXPECT_FALSE(cache.load(key_));
  fs::remove(dir_.string() + "-file");
}

} // namespace

// A temporary directory of the running test's own, /tmp/canopy_<prefix>_<test name>, created.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace canopy::test {

inline std::filesystem::path test_temp_dir(const std::string& prefix) {
  auto d = std::filesystem::temp_directory_path() /
           ("canopy_" + prefix + "_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
  std::filesystem::create_directories(d);
  return d;
}

} // namespace canopy::test

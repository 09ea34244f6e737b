// TREELOD_GTEST_SKIP: gtest patterns (A.b:C.*) left out of a test binary's run, whatever
// --gtest_filter selects. ctest runs every gtest binary a suite per process
// (cmake/TreeLodSuiteTests.cmake), so tests/run.sh names the tests a stage leaves out here, not
// with ctest -E.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

namespace TreeLod::test
{
    /// Call after ::testing::InitGoogleTest.
    inline void skipTestsNamedInEnvironment()
    {
        const char* skip = std::getenv("TREELOD_GTEST_SKIP");
        if (!skip || !*skip)
            return;
        std::string filter = ::testing::GTEST_FLAG(filter);
        filter += (filter.find('-') == std::string::npos ? "-" : ":") + std::string(skip);
        ::testing::GTEST_FLAG(filter) = filter;
    }
}

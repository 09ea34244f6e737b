// main() of the Ogre test binaries: registers OgreEnvironment, whose TearDown destroys the
// kept assets and the headless Root before main() returns (OgreTestSupport.h).
#include "OgreTestSupport.h"

#include <cstdlib>
#include <string>

// ASan trees (tests/run.sh): no LeakSanitizer in these binaries. OGRE unloads its render system
// and libGL unloads Mesa's driver before the leak check at exit, so the few one-time allocations
// made there can be neither named nor suppressed. The core binaries keep it.
extern "C" __attribute__((used, visibility("default"))) const char* __asan_default_options()
{
    return "detect_leaks=0";
}

int main(int argc, char** argv)
{
    ::testing::InitGoogleTest(&argc, argv);
    // TREELOD_GTEST_SKIP: gtest patterns (A.b:C.*) left out of the run, whatever --gtest_filter
    // selects. ctest runs these binaries a suite at a time, so the sanitizer trees name the tests
    // they leave out here (tests/run.sh), not with ctest -E.
    if (const char* skip = std::getenv("TREELOD_GTEST_SKIP"); skip && *skip)
    {
        std::string filter = ::testing::GTEST_FLAG(filter);
        filter += (filter.find('-') == std::string::npos ? "-" : ":") + std::string(skip);
        ::testing::GTEST_FLAG(filter) = filter;
    }
    ::testing::AddGlobalTestEnvironment(new TreeLod::OgreEnvironment);
    return RUN_ALL_TESTS();
}

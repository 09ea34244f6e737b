// main() of the Ogre test binaries: registers OgreEnvironment, whose TearDown destroys the
// kept assets and the headless Root before main() returns (OgreTestSupport.h).
#include "OgreTestSupport.h"
#include "TestFilter.h"

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
    TreeLod::test::skipTestsNamedInEnvironment();
    ::testing::AddGlobalTestEnvironment(new TreeLod::OgreEnvironment);
    return RUN_ALL_TESTS();
}

// main() of the test binaries without Ogre (the Ogre ones have tests/ogre/OgreTestMain.cpp).
#include "TestFilter.h"

int main(int argc, char** argv)
{
    ::testing::InitGoogleTest(&argc, argv);
    TreeLod::test::skipTestsNamedInEnvironment();
    return RUN_ALL_TESTS();
}

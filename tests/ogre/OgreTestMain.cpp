// main() of the Ogre test binaries: registers OgreEnvironment, whose TearDown destroys the
// kept assets and the headless Root before main() returns (OgreTestSupport.h).
#include "OgreTestSupport.h"

int main(int argc, char** argv)
{
    ::testing::InitGoogleTest(&argc, argv);
    ::testing::AddGlobalTestEnvironment(new TreeLod::OgreEnvironment);
    return RUN_ALL_TESTS();
}

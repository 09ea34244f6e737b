// Entry points of Plugin_TreeLod.so for Root::loadPlugin (only these live here).
#include "TreeLod/TreeLodPlugin.h"

#include <OgreRoot.h>

namespace
{
    TreeLod::TreeLodPlugin* gPlugin = nullptr;
}

extern "C" __attribute__((visibility("default"))) void dllStartPlugin()
{
    gPlugin = new TreeLod::TreeLodPlugin();
    Ogre::Root::getSingleton().installPlugin(gPlugin);
}

extern "C" __attribute__((visibility("default"))) void dllStopPlugin()
{
    Ogre::Root::getSingleton().uninstallPlugin(gPlugin);
    delete gPlugin;
    gPlugin = nullptr;
}

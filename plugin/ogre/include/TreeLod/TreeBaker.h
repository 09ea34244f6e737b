// TreeBaker: how Plugin_TreeLod reaches a baker without linking one (docs/architecture.md,
// "Runtime vs bake"). An application that can bake (the CLI, the sample browser, a user's tool)
// registers one with TreeAssetManager::setBaker; TreeAssetManager::require then asks it for a
// package holding the chunks a scene needs ("model only what a scene requires") and loads it.
// Without a registered baker, require() throws, naming the source.
#pragma once

#include <OgreCommon.h>

#include <vector>

namespace TreeLod
{
    class TreeBaker
    {
    public:
        virtual ~TreeBaker() = default;

        /// The path of a package that holds the chunks of `techniques` (bake technique names,
        /// BakeTechniques.h, and "reference") for
        /// `source` (a tree file or a generator source such as "preset:oak?seed=1"), baking the
        /// missing ones. Throws Ogre::Exception with a message naming the source on failure.
        virtual Ogre::String requirePackage(const Ogre::String& source, const std::vector<Ogre::String>& techniques) = 0;
    };
}

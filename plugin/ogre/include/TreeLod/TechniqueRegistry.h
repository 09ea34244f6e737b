// TechniqueRegistry: the LoD techniques this plugin can draw a TreeAsset with.
//
// One entry per technique: its name on the command line and in scene scripts, the
// package chunk it needs, the MovableObject type that draws it, and a function that
// creates that object. "mesh" (the polygonal reference, an Entity) is registered by the
// plugin itself; each technique issue adds one line in TechniqueRegistry.cpp.
#pragma once

#include <OgreCommon.h>
#include <OgreSingleton.h>

#include <functional>
#include <vector>

namespace Ogre
{
    class MovableObject;
    class SceneManager;
}

namespace TreeLod
{
    class TreeAsset;

    struct TechniqueInfo
    {
        Ogre::String name;           ///< "mesh", "billboardcloud", "lodf", ...
        Ogre::String description;
        Ogre::String chunkTechnique; ///< package chunk it draws from ("reference", ...)
        Ogre::String movableType;    ///< factory type of the object it creates
        /// Create the object for `asset` (loaded). params as for createMovableObject.
        std::function<Ogre::MovableObject*(Ogre::SceneManager& sceneManager, const Ogre::String& name,
                                           TreeAsset& asset, const Ogre::NameValuePairList& params)>
            create;
    };

    class TechniqueRegistry : public Ogre::Singleton<TechniqueRegistry>
    {
    public:
        TechniqueRegistry(); ///< registers the built-in techniques

        /// Add or replace a technique.
        void add(TechniqueInfo info);
        /// nullptr when unknown.
        const TechniqueInfo* find(const Ogre::String& name) const;
        const std::vector<TechniqueInfo>& getTechniques() const { return mTechniques; }
        /// "mesh, billboardcloud, ..." for messages.
        Ogre::String describe() const;

        /// Create `technique` for `asset` or throw Ogre::InvalidParametersException naming
        /// the known techniques.
        Ogre::MovableObject* createInstance(const Ogre::String& technique, Ogre::SceneManager& sceneManager,
                                            const Ogre::String& name, TreeAsset& asset,
                                            const Ogre::NameValuePairList& params = {}) const;

        static TechniqueRegistry& getSingleton();
        static TechniqueRegistry* getSingletonPtr();

    private:
        std::vector<TechniqueInfo> mTechniques;
    };
}

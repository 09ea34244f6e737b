#include "TreeLod/TechniqueRegistry.h"

#include "TreeLod/BillboardCloudTree.h"
#include "TreeLod/FoliageLodTree.h"
#include "TreeLod/TreeAsset.h"

#include <OgreEntity.h>
#include <OgreException.h>
#include <OgreSceneManager.h>

template <> TreeLod::TechniqueRegistry* Ogre::Singleton<TreeLod::TechniqueRegistry>::msSingleton = nullptr;

namespace TreeLod
{
    TechniqueRegistry& TechniqueRegistry::getSingleton() { return *msSingleton; }
    TechniqueRegistry* TechniqueRegistry::getSingletonPtr() { return msSingleton; }

    TechniqueRegistry::TechniqueRegistry()
    {
        // The polygonal reference: every comparison in this project is against it.
        add({"mesh", "polygonal reference: bark with MeshLodGenerator levels, every leaf", "reference",
             Ogre::EntityFactory::FACTORY_TYPE_NAME,
             [](Ogre::SceneManager& sm, const Ogre::String& name, TreeAsset& asset, const Ogre::NameValuePairList&) {
                 return static_cast<Ogre::MovableObject*>(sm.createEntity(name, asset.getReferenceMesh()));
             }});
        // paper 004: continuous foliage LoD by leaf collapse.
        add({"lodf", "LoDF: every leaf geometric, leaf count continuous with screen size (paper 004)",
             FOLIAGE_LOD_CHUNK, FoliageLodTreeFactory::FACTORY_TYPE_NAME,
             [](Ogre::SceneManager& sm, const Ogre::String& name, TreeAsset& asset, const Ogre::NameValuePairList& params) {
                 Ogre::NameValuePairList all = params;
                 all["asset"] = asset.getName();
                 all["group"] = asset.getGroup();
                 return sm.createMovableObject(name, FoliageLodTreeFactory::FACTORY_TYPE_NAME, &all);
             }});
        // paper 000: billboard clouds with multi-layered indirect texturing, and the classic cloud.
        for (const bool classic : {false, true})
            add({classic ? CLASSIC_BILLBOARD_CLOUD_CHUNK : BILLBOARD_CLOUD_CHUNK,
                 classic ? "classic billboard cloud: one RGBA texture per billboard, the baseline of paper 000 Fig. 13"
                         : "billboard clouds with multi-layered indirect texturing and shader LoD (paper 000)",
                 classic ? CLASSIC_BILLBOARD_CLOUD_CHUNK : BILLBOARD_CLOUD_CHUNK,
                 BillboardCloudTreeFactory::FACTORY_TYPE_NAME,
                 [classic](Ogre::SceneManager& sm, const Ogre::String& name, TreeAsset& asset,
                           const Ogre::NameValuePairList& params) {
                     Ogre::NameValuePairList all = params;
                     all["asset"] = asset.getName();
                     all["group"] = asset.getGroup();
                     all["classic"] = classic ? "true" : "false";
                     return sm.createMovableObject(name, BillboardCloudTreeFactory::FACTORY_TYPE_NAME, &all);
                 }});
        // Technique issues add their line here.
    }

    void TechniqueRegistry::add(TechniqueInfo info)
    {
        for (TechniqueInfo& t : mTechniques)
            if (t.name == info.name)
            {
                t = std::move(info);
                return;
            }
        mTechniques.push_back(std::move(info));
    }

    const TechniqueInfo* TechniqueRegistry::find(const Ogre::String& name) const
    {
        for (const TechniqueInfo& t : mTechniques)
            if (t.name == name)
                return &t;
        return nullptr;
    }

    Ogre::String TechniqueRegistry::describe() const
    {
        Ogre::String out;
        for (const TechniqueInfo& t : mTechniques)
            out += (out.empty() ? "" : ", ") + t.name;
        return out;
    }

    Ogre::MovableObject* TechniqueRegistry::createInstance(const Ogre::String& technique,
                                                           Ogre::SceneManager& sceneManager,
                                                           const Ogre::String& name, TreeAsset& asset,
                                                           const Ogre::NameValuePairList& params) const
    {
        const TechniqueInfo* info = find(technique);
        if (!info)
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                        "unknown technique '" + technique + "' (known: " + describe() + ")",
                        "TechniqueRegistry::createInstance");
        return info->create(sceneManager, name, asset, params);
    }
}

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

    namespace
    {
        /// A create function for a tree object factory: `params` plus the asset (and `extra`).
        decltype(TechniqueInfo::create) byFactory(const Ogre::String& type, Ogre::NameValuePairList extra = {})
        {
            return [type, extra](Ogre::SceneManager& sm, const Ogre::String& name, TreeAsset& asset,
                                 const Ogre::NameValuePairList& params) {
                Ogre::NameValuePairList all = params;
                all["asset"] = asset.getName();
                all["group"] = asset.getGroup();
                for (const auto& [key, value] : extra)
                    all[key] = value;
                return sm.createMovableObject(name, type, &all);
            };
        }
    }

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
             byFactory(FoliageLodTreeFactory::FACTORY_TYPE_NAME)});
        // paper 000: billboard clouds with multi-layered indirect texturing, and the classic cloud.
        add({BILLBOARD_CLOUD_CHUNK,
             "billboard clouds with multi-layered indirect texturing and shader LoD (paper 000)",
             BILLBOARD_CLOUD_CHUNK, BillboardCloudTreeFactory::FACTORY_TYPE_NAME,
             byFactory(BillboardCloudTreeFactory::FACTORY_TYPE_NAME, {{"classic", "false"}})});
        add({CLASSIC_BILLBOARD_CLOUD_CHUNK,
             "classic billboard cloud: one RGBA texture per billboard, the baseline of paper 000 Fig. 13",
             CLASSIC_BILLBOARD_CLOUD_CHUNK, BillboardCloudTreeFactory::FACTORY_TYPE_NAME,
             byFactory(BillboardCloudTreeFactory::FACTORY_TYPE_NAME, {{"classic", "true"}})});
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

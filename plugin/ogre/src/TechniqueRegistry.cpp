#include "TreeLod/TechniqueRegistry.h"

#include "TreeLod/TreeAsset.h"

#include <OgreException.h>
#include <OgreSceneManager.h>

#include <algorithm>

namespace TreeLod
{
    namespace
    {
        std::vector<void (*)(TechniqueRegistry&)>& registrations()
        {
            static std::vector<void (*)(TechniqueRegistry&)> functions;
            return functions;
        }

        TechniqueRegistry*& made()
        {
            static TechniqueRegistry* registry = nullptr;
            return registry;
        }
    }

    TechniqueRegistry& TechniqueRegistry::getSingleton()
    {
        static TechniqueRegistry registry;
        return registry;
    }

    TechniqueRegistry::Registration::Registration(void (*registerTechnique)(TechniqueRegistry& registry))
    {
        if (TechniqueRegistry* registry = made())
        {
            registerTechnique(*registry);
            registry->sortTechniques();
        }
        else
            registrations().push_back(registerTechnique);
    }

    TechniqueRegistry::TechniqueRegistry()
    {
        for (void (*registerTechnique)(TechniqueRegistry&) : registrations())
            registerTechnique(*this);
        sortTechniques();
        made() = this;
    }

    void TechniqueRegistry::sortTechniques()
    {
        // Static initialisation runs the registrations in link order: list "mesh", the reference
        // every comparison is made against, first, then the others by name.
        std::stable_sort(mTechniques.begin(), mTechniques.end(), [](const TechniqueInfo& a, const TechniqueInfo& b) {
            return std::make_pair(a.name != REFERENCE_TECHNIQUE, a.name) < std::make_pair(b.name != REFERENCE_TECHNIQUE, b.name);
        });
    }

    decltype(TechniqueInfo::create) TechniqueRegistry::byFactory(const Ogre::String& type,
                                                                 Ogre::NameValuePairList extra)
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

    const TechniqueInfo& TechniqueRegistry::get(const Ogre::String& name, const Ogre::String& element,
                                                const char* source) const
    {
        const TechniqueInfo* info = find(name);
        if (!info)
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                        element + "unknown technique '" + name + "' (known: " + describe() + ")", source);
        return *info;
    }

    Ogre::String TechniqueRegistry::describe() const
    {
        Ogre::String out;
        for (const TechniqueInfo& t : mTechniques)
            out += (out.empty() ? "" : ", ") + t.name;
        return out;
    }

    const TechniqueInfo& TechniqueRegistry::getFloor() const
    {
        for (const TechniqueInfo& t : mTechniques)
            if (t.roles.floor)
                return t;
        OGRE_EXCEPT(Ogre::Exception::ERR_ITEM_NOT_FOUND,
                    "no registered technique is the floor (TechniqueRoles::floor; known: " + describe() + ")",
                    "TechniqueRegistry::getFloor");
    }

    void TechniqueRegistry::addBaseline(BaselineInfo info)
    {
        for (BaselineInfo& b : mBaselines)
            if (b.name == info.name)
            {
                b = std::move(info);
                return;
            }
        mBaselines.push_back(std::move(info));
    }

    const BaselineInfo* TechniqueRegistry::findBaseline(const Ogre::String& name) const
    {
        for (const BaselineInfo& b : mBaselines)
            if (b.name == name)
                return &b;
        return nullptr;
    }

    Ogre::MovableObject* TechniqueRegistry::createInstance(const Ogre::String& technique,
                                                           Ogre::SceneManager& sceneManager,
                                                           const Ogre::String& name, TreeAsset& asset,
                                                           const Ogre::NameValuePairList& params) const
    {
        return get(technique, "", "TechniqueRegistry::createInstance").create(sceneManager, name, asset, params);
    }
}

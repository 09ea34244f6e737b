// ObjectParams: reading the createMovableObject parameters of the tree objects' factories
// (FoliageLodTree, BillboardCloudTree, ImpostorTree, a technique's own): one wording for every bad parameter
// ("parameter 'key': 'value' is not ...") and one way to load the `asset` in `group`.
#pragma once

#include "TreeLod/TreeAssetManager.h"

#include <OgreCommon.h>
#include <OgreException.h>

#include <cstdlib>
#include <string>

namespace TreeLod
{
    class ObjectParams
    {
    public:
        /// `params` may be null (no parameters); `source` names the factory in exceptions.
        ObjectParams(const Ogre::NameValuePairList* params, const char* source) : mParams(params), mSource(source) {}

        /// Throws Ogre::InvalidParametersException: "parameter 'key': 'value' is not <expected>".
        [[noreturn]] void bad(const char* key, const Ogre::String& value, const Ogre::String& expected) const
        {
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                        Ogre::String("parameter '") + key + "': '" + value + "' is not " + expected, mSource);
        }

        /// The value of `key`, or nullptr when absent.
        const Ogre::String* find(const char* key) const
        {
            if (!mParams)
                return nullptr;
            auto it = mParams->find(key);
            return it == mParams->end() ? nullptr : &it->second;
        }

        /// false when absent; a number in [lo, hi] or an exception.
        bool number(const char* key, double lo, double hi, double& out) const
        {
            const Ogre::String* value = find(key);
            if (!value)
                return false;
            char* end = nullptr;
            out = std::strtod(value->c_str(), &end);
            if (value->empty() || *end != '\0' || !(out >= lo && out <= hi))
                bad(key, *value, "a number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
            return true;
        }

        /// false when absent; "true" or "false" or an exception.
        bool flag(const char* key, bool& out) const
        {
            const Ogre::String* value = find(key);
            if (!value)
                return false;
            if (*value != "true" && *value != "false")
                bad(key, *value, "true or false");
            out = *value == "true";
            return true;
        }

        /// The asset named by the required `asset` parameter, loaded in `group` (default:
        /// autodetect). Throws naming `objectName` when `asset` is missing.
        TreeAssetPtr loadAsset(const Ogre::String& objectName, const char* type) const
        {
            const Ogre::String* asset = find("asset");
            if (!asset)
                OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                            Ogre::String(type) + " '" + objectName + "': parameter 'asset' is required", mSource);
            const Ogre::String* group = find("group");
            return TreeAssetManager::getSingleton().load(
                *asset, group ? *group : Ogre::ResourceGroupManager::AUTODETECT_RESOURCE_GROUP_NAME);
        }

    private:
        const Ogre::NameValuePairList* mParams;
        const char* mSource;
    };
}

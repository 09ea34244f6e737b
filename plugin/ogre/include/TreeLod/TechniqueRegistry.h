// TechniqueRegistry: the LoD techniques this plugin can draw a TreeAsset with, the Ogre half of
// the technique seam (docs/architecture.md, "The technique seam").
//
// One TechniqueInfo per technique: its name on the command line and in scene scripts, the
// package chunk it draws from, the MovableObject type that draws a single tree and the factory
// that makes it, the ForestLevelProvider that draws it as a Forest level, and what the sample
// browser shows of an object's state. A technique registers itself from its own source file with
// one namespace-scope TechniqueRegistry::Registration; the registry runs every registration when
// the registry is first used. TreeAsset, the Forest, ForestScene, `treelod render`/`bench` and the
// browser iterate the registry and name no technique; what differs between techniques in the trade
// (auto candidacy, default bands, the floor, render options) is each one's TechniqueRoles, and
// the measurement baselines drawn without a technique (the speed floors) are BaselineInfos. The
// registry is one per process, made on first use (no Ogre::Root needed: a bench lists techniques
// before it renders); the plugin adds the factories to Root when it installs.
#pragma once

#include "TreeLod/ForestBaseline.h"
#include "TreeLod/ForestLevelProvider.h"

#include <OgreCommon.h>

#include <functional>
#include <memory>
#include <vector>

namespace Ogre
{
    class MovableObject;
    class MovableObjectFactory;
    class SceneManager;
}

namespace TreeLod
{
    class TreeAsset;

    /// The technique every measurement compares against: the polygonal reference (an Entity).
    constexpr const char* REFERENCE_TECHNIQUE = "mesh";

    /// One line of an object's state for the sample browser: label, a bar filled to `fraction`
    /// (none when < 0), suffix; e.g. {"leaves ", 0.25, " 300/1200"}.
    struct TechniqueStateLine
    {
        Ogre::String label;
        double fraction = -1.0;
        Ogre::String suffix;
    };

    /// An object parameter that `treelod render` offers as `--<flag> VALUE`, passed to the
    /// technique's `create` as params[name].
    struct TechniqueParameter
    {
        Ogre::String name;        ///< the object's parameter ("leaves")
        Ogre::String flag;        ///< the option, without dashes ("leaves", "pixels-per-leaf")
        Ogre::String description; ///< its help text
    };

    /// What a technique is in the trade, besides how it draws. The Forest, the bench, the corpus
    /// study and the CLI read these instead of naming techniques; `treelod info --techniques`
    /// lists them.
    struct TechniqueRoles
    {
        bool floor = false;         ///< the cheapest level: the bench's floor, the default bands' last (one technique)
        bool autoCandidate = false; ///< budgeted auto may choose its levels (Forest::getAutoTechniques)
        /// Tree height on screen (pixels) from which its band of Forest::getAutoBands starts; < 0: not
        /// in the default bands (the floor's band reaches 0).
        float defaultBandMinHeight = -1.0f;
        bool benchDefault = false; ///< drawn by `treelod bench` and studied by the corpus study by default
        /// Non-empty: every bench run is compared with this one, which the plots call so.
        Ogre::String comparisonLabel;
        char plotMarker = 'o'; ///< its point in the bench's trade plot (a matplotlib marker)
        std::vector<TechniqueParameter> parameters; ///< `treelod render` options of its objects
        /// The technique its paper measures it against, baked at equal memory (the corpus study
        /// compares the two where both run); empty if none.
        Ogre::String paperBaseline;
        /// Object parameters under which it shades as the polygonal reference does (which has no
        /// ambient occlusion term), for image-error studies.
        Ogre::NameValuePairList referenceShadingParams;
    };

    /// A measurement baseline drawn without the Forest (ForestBaseline.h): the bench compares
    /// every technique with it; a scene script or --techniques names it as a technique.
    struct BaselineInfo
    {
        Ogre::String name;            ///< its name in --techniques and scene scripts ("entities", ...)
        Ogre::String comparisonLabel; ///< what the plots call it
        char plotMarker = 'o';        ///< its point in the trade plot (a matplotlib marker)
        Ogre::String chunkTechnique;  ///< the package chunk it draws from
        ForestBaselineFactory create; ///< draws a scene's trees
        bool oneObjectPerTree = false; ///< one Ogre object per tree: runs skip it above a tree count (--entity-limit)
    };

    struct TechniqueInfo
    {
        Ogre::String name;           ///< "mesh" or the name a technique registers
        Ogre::String description;
        Ogre::String chunkTechnique; ///< package chunk it draws from ("reference", ...)
        Ogre::String movableType;    ///< factory type of the object it creates
        /// Create the object for `asset` (loaded). params as for createMovableObject.
        std::function<Ogre::MovableObject*(Ogre::SceneManager& sceneManager, const Ogre::String& name,
                                           TreeAsset& asset, const Ogre::NameValuePairList& params)>
            create;
        /// The factory of movableType, added to Ogre::Root by the plugin (several techniques may
        /// share one); null when Ogre provides the type (Entity).
        std::shared_ptr<Ogre::MovableObjectFactory> factory;
        /// Draws the technique as a Forest level; null when it cannot be one.
        std::shared_ptr<ForestLevelProvider> forestLevels;
        /// The state of an object `create` made (level, leaves, ...), for the sample browser's
        /// level panel; may be empty.
        std::function<std::vector<TechniqueStateLine>(Ogre::MovableObject& object)> describeState;
        TechniqueRoles roles; ///< what it is in the trade (auto candidate, default band, floor, ...)
        /// Set the level transition length of an object `create` made (ObjectTransition.h; throws
        /// as its setLodTransition); null where the object has one level or a continuous one.
        std::function<void(Ogre::MovableObject& object, float length)> setLodTransition;
    };

    class TechniqueRegistry
    {
    public:
        /// A technique's registration: a function adding its TechniqueInfo(s), run when the registry
        /// is made (or at once if it exists). One namespace-scope instance in the technique's source.
        struct Registration
        {
            explicit Registration(void (*registerTechnique)(TechniqueRegistry& registry));
        };

        TechniqueRegistry(const TechniqueRegistry&) = delete;
        TechniqueRegistry& operator=(const TechniqueRegistry&) = delete;

        /// Add or replace a technique.
        void add(TechniqueInfo info);
        /// nullptr when unknown.
        const TechniqueInfo* find(const Ogre::String& name) const;
        /// The technique named `name` or Ogre::InvalidParametersException "<element>unknown technique
        /// '<name>' (known: ...)" from `source`.
        const TechniqueInfo& get(const Ogre::String& name, const Ogre::String& element = "",
                                 const char* source = "TechniqueRegistry::get") const;
        const std::vector<TechniqueInfo>& getTechniques() const { return mTechniques; }
        /// "mesh, <technique>, ..." for messages.
        Ogre::String describe() const;
        /// The technique whose roles say floor, or Ogre::ItemIdentityException when none is registered.
        const TechniqueInfo& getFloor() const;

        /// Add or replace a measurement baseline (kept in the order added).
        void addBaseline(BaselineInfo info);
        /// nullptr when unknown.
        const BaselineInfo* findBaseline(const Ogre::String& name) const;
        const std::vector<BaselineInfo>& getBaselines() const { return mBaselines; }

        /// Create `technique` for `asset` or throw Ogre::InvalidParametersException naming
        /// the known techniques.
        Ogre::MovableObject* createInstance(const Ogre::String& technique, Ogre::SceneManager& sceneManager,
                                            const Ogre::String& name, TreeAsset& asset,
                                            const Ogre::NameValuePairList& params = {}) const;

        /// A create function for a technique whose factory takes `asset` and `group` parameters:
        /// `params` plus the asset (and `extra`).
        static decltype(TechniqueInfo::create) byFactory(const Ogre::String& type, Ogre::NameValuePairList extra = {});

        /// The process's registry (made on first call, running every Registration).
        static TechniqueRegistry& getSingleton();
        static TechniqueRegistry* getSingletonPtr() { return &getSingleton(); }

    private:
        TechniqueRegistry();
        void sortTechniques();

        std::vector<TechniqueInfo> mTechniques;
        std::vector<BaselineInfo> mBaselines;
    };
}

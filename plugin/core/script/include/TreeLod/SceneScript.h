// SceneScript: samples/scenes/*.json, the scenes that `treelod bench`, the Forest and the
// sample browser run. docs/scene-format.md documents the format key by key.
//
// Contract:
// - Units: metres, degrees in the file (radians in PlacedTree::rotation), seconds for time.
//   +Y up; the ground is a square of `size` metres centred at the origin.
// - Errors name the file, the line and column (1-based, columns count bytes) and the key as
//   a JSON pointer: "scene.json: line 12, column 9, key /placements/0/random/count: must be
//   >= 1". JSON syntax errors give line and column only (NaN and Infinity are not JSON); a
//   number beyond a double (1e999) is an error at its key. Unknown keys, duplicate keys, wrong
//   types, out-of-range values and keyframe times that do not increase are errors. A missing
//   required key is reported at the object that lacks it. Comments (// and /* */) are allowed.
// - Paths (species sources, the heightfield image, instance files) are relative to the script's
//   folder and stored resolved; species files, the heightfield image and instance files must
//   exist when the script loads. The heightfield image is read by the caller's GreyImageReader
//   (GreyImage.h): this library links the runtime only (docs/architecture.md, "Runtime vs bake").
// - Instance files (a placement's "file": CSV, one tree a line, see docs/scene-format.md):
//   errors name the CSV file, the line (1-based) and the column by its header name:
//   "trees.csv: line 12, column scale: 0 must be finite and > 0". One read of the file,
//   std::from_chars per number: 0.2 s for a million lines (2-core test machine).
// - Bounds on the whole scene, so no script costs more than about a GB and a few seconds:
//   at most 10,000,000 trees in all placements together (generatePlacements makes them all at
//   once) and 64 exclusion areas (each is tested against 512 x 512 points of its placement's
//   area). The placement that passes a bound is the error, at its count, density, positions,
//   file or exclude key.
// - Placements are deterministic: the same script and options give the same trees on any
//   machine (own sampling over std::mt19937, no std:: distributions, no threads).
// - The camera path is a centripetal Catmull-Rom spline (alpha 0.5, Barry-Goldman form) through
//   the keyframe positions and, separately, the targets; each segment's time maps linearly
//   onto its knot interval, so the path passes through every keyframe at its time, is
//   continuous with a continuous direction, and may change speed at a keyframe. End segments,
//   and segments next to a repeated position (a hold: the camera stops and turns), use mirrored
//   phantom points, so a hold is a corner. Outside the keyframe times the camera holds still.
//   Splines overshoot: keep a low camera's neighbouring keyframes low too.
#pragma once

#include "TreeLod/Camera.h"
#include "TreeLod/ForestInstances.h"
#include "TreeLod/GreyImage.h"
#include "TreeLod/LevelSelection.h"
#include "TreeLod/Result.h"
#include "TreeLod/WindModel.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace TreeLod
{
    struct SceneGround
    {
        enum class Kind
        {
            Plane,     ///< y = 0 everywhere
            Heightfield ///< grey image over the square; y = heightScale * grey (0..1), bilinear
        };
        Kind kind = Kind::Plane;
        float size = 1000.0f;      ///< side of the square in metres, centred at the origin
        std::string image;         ///< heightfield: resolved image path
        float heightScale = 0.0f;  ///< heightfield: metres at grey 1
        int heightsWidth = 0;      ///< heightfield: image columns (x from -size/2 to +size/2)
        int heightsHeight = 0;     ///< heightfield: image rows (z from -size/2 to +size/2)
        std::vector<float> heights; ///< heightfield: grey 0..1 (red channel), row-major
    };

    /// The technique a species is drawn with up to a distance or down to a screen size.
    struct TechniqueBand
    {
        std::string technique; ///< registry name ("mesh" or a registered technique)
        float maxDistance = 0.0f; ///< metres; 0 = open-ended (last band) or the band uses minPixels
        float minPixels = 0.0f;   ///< tree height on screen in pixels; 0 = open-ended or maxDistance
    };

    struct SceneSpecies
    {
        std::string name;
        std::string source;      ///< resolved file path, or "" for a generator preset
        std::string preset;      ///< a TreePreset name (TreePreset.h) when source is "preset:NAME"
        std::uint32_t seed = 1;  ///< preset only
        std::uint32_t leaves = 0; ///< preset only, 0 = preset default
        float height = 0.0f;     ///< preset only, metres, 0 = preset default
        bool autoTechnique = true; ///< "techniques": "auto": the Forest chooses per screen size
        std::vector<TechniqueBand> bands; ///< otherwise: near to far; all by distance or all by pixels
        float scaleMin = 1.0f;   ///< uniform scale of each instance, drawn in [scaleMin, scaleMax]
        float scaleMax = 1.0f;
    };

    /// A rectangle [min, max] or a disc (with an optional hole) in the ground plane (x, z).
    struct SceneArea
    {
        enum class Kind
        {
            Rect,
            Disc
        };
        Kind kind = Kind::Rect;
        glm::vec2 min{0.0f}, max{0.0f};  ///< rect
        glm::vec2 centre{0.0f};          ///< disc
        float radius = 0.0f, innerRadius = 0.0f; ///< disc; innerRadius > 0 makes a ring

        bool contains(const glm::vec2& p) const;
        float areaM2() const;
    };

    struct ScenePlacement
    {
        std::vector<std::uint32_t> species; ///< indices into SceneScript::species; random picks one per tree
        bool random = false;
        /// explicit ("positions" or "file"): x, z, rotation (radians), scale
        std::vector<glm::vec4> positions;
        /// explicit, per entry of `positions`: its species (index into SceneScript::species);
        /// empty = species[0] for all ("positions" take one species, a file may name several)
        std::vector<std::uint32_t> positionSpecies;
        /// explicit, per entry of `positions`: y in metres, NaN = on the ground; empty = all on the ground
        std::vector<float> positionY;
        std::string file; ///< "file": the resolved CSV path; "" otherwise
        /// random:
        std::uint32_t seed = 1;
        std::uint32_t count = 0;   ///< trees; from density * free area when the script gives a density
        float density = 0.0f;     ///< trees per hectare of the area outside `exclude`, 0 = count given
        SceneArea area;
        std::vector<SceneArea> exclude; ///< kept free (a plaza, a road)
        float clumping = 0.0f;    ///< 0 uniform .. 1 tight clusters (Thomas process, see .cpp)
        /// m^2 of `area` outside `exclude`, sampled once by the parser (0 in a placement built in
        /// code: generatePlacements() then samples it itself)
        double freeAreaM2 = 0.0;
    };

    struct SceneSun
    {
        glm::vec3 direction{0.0f, 1.0f, 0.0f}; ///< unit, towards the sun
        glm::vec3 colour{0.85f, 0.82f, 0.75f};
        glm::vec3 ambient{0.35f, 0.38f, 0.45f};
    };

    struct SceneShadows
    {
        bool enabled = false;
        int textureSize = 2048;       ///< power of two, 256..16384
        std::string camera = "focused"; ///< "focused" | "lispsm" | "pssm" (Ogre's shadow camera setups; pssm: 3 splits)
        float lodBias = 1.0f;           ///< Forest::setShadowLodBias: < 1 = coarser casters than the view
    };

    /// "lod": how `auto` species choose levels (docs/scene-format.md).
    struct SceneLod
    {
        static constexpr float DEFAULT_MAX_ERROR = DEFAULT_ERROR_BUDGET;
        static constexpr float DEFAULT_SHADOW_MAX_ERROR = DEFAULT_SHADOW_ERROR_BUDGET;
        /// Error budget of budgeted auto (Forest::setErrorBudget): FLIP over the tree's box above
        /// the polygonal reference's own, in [0, 1].
        float maxError = DEFAULT_MAX_ERROR;
        /// The shadow casters' own error budget (Forest::setShadowErrorBudget), in [0, 1].
        float shadowMaxError = DEFAULT_SHADOW_MAX_ERROR;
        /// Frame budget of budgeted auto (Forest::setFrameBudgetMs), ms; 0: none.
        float frameBudgetMs = 0.0f;
        /// GPU memory budget of budgeted auto's levels (Forest::setMemoryBudget), megabytes (10^6
        /// bytes); 0: none.
        float memoryBudgetMB = 0.0f;
        /// Level transitions (Forest::setLodTransition) of every species, in [0, 1]; 0: hard switches.
        float transition = ForestInstances::DEFAULT_TRANSITION;
        /// Occlusion between the trees (Forest::setOcclusion).
        bool occlusion = true;
    };

    struct SceneKeyframe
    {
        double time = 0.0; ///< seconds, strictly increasing
        glm::vec3 position{0.0f};
        glm::vec3 target{0.0f};
    };

    struct SceneCamera
    {
        float fovYDegrees = 45.0f;
        float nearClip = 0.05f;
        float farClip = 10000.0f;
        bool linear = false; ///< "interpolation": "linear"; default "catmull-rom"
        std::vector<SceneKeyframe> keyframes; ///< at least one
    };

    struct SceneScript
    {
        std::string file;    ///< path or label it came from
        std::string name;
        std::string description;
        SceneGround ground;
        std::vector<SceneSpecies> species;
        std::vector<ScenePlacement> placements;
        SceneSun sun;
        SceneShadows shadows;
        SceneLod lod;
        /// "wind": the wind every tree follows (TreeLod/WindModel.h), on the clock of the camera path
        /// (frameTime): frames are reproducible. Default calm.
        WindParameters wind;
        SceneCamera camera;
        int width = 1280, height = 720; ///< "resolution": [w, h]
        std::uint32_t frames = 1;       ///< frames spread over the camera path
        /// Optional "counts" sweep (table2.json): total tree counts, one run each; see PlacementOptions.
        std::vector<std::uint32_t> counts;
    };

    /// Read and check a scene script; paths inside resolve against the script's folder.
    /// `readImage` reads a heightfield ground's image; empty: a heightfield script fails at its
    /// "image" key ("no image reader given (...)"), plane scripts need none.
    Result<SceneScript> loadSceneScript(const std::string& path, const GreyImageReader& readImage = {});

    /// Same from text; `label` names it in errors, `baseDir` resolves relative paths ("" = cwd).
    Result<SceneScript> parseSceneScript(const std::string& text, const std::string& label,
                                         const std::string& baseDir, const GreyImageReader& readImage = {});

    /// One tree of the scene, as the Forest takes it.
    struct PlacedTree
    {
        std::uint32_t species = 0; ///< index into SceneScript::species
        glm::vec3 position{0.0f};  ///< y on the ground
        float rotation = 0.0f;     ///< radians about +Y
        float scale = 1.0f;
    };

    struct PlacementOptions
    {
        /// Total number of trees (one entry of `counts`), 0 = as the script says. Explicit
        /// placements ("positions" and "file") are kept (the first totalCount of them if there are more); random
        /// placements share the rest in proportion to their own counts.
        std::uint32_t totalCount = 0;
        /// `treelod bench --scale S`: every random placement's tree count times S (rounded, at
        /// least 1) inside the same area, so the scene keeps its extent and layout and only
        /// thins out; explicit placements are kept. Applied after totalCount. > 0.
        double scale = 1.0;
    };

    /// All trees: explicit placements first, then random ones, in script order.
    std::vector<PlacedTree> generatePlacements(const SceneScript& script, const PlacementOptions& options = {});

    /// Ground height at (x, z): 0 on a plane; bilinear in the heightfield, clamped at its edges.
    float groundHeight(const SceneGround& ground, float x, float z);

    /// The camera at `time` seconds (clamped to the keyframes' times).
    CameraSpec cameraAt(const SceneScript& script, double time);

    /// Time of frame `frame` when `frameCount` frames (0 = script.frames) spread evenly from
    /// the first keyframe's time to the last's, both included.
    double frameTime(const SceneScript& script, std::uint32_t frame, std::uint32_t frameCount = 0);

    /// The script's sun as the renderers' lighting (background stays the default).
    LightingSpec sceneLighting(const SceneScript& script);
}

// ErrorCurveMeasurer: the error curves of an asset (ErrorCurves.h), measured at bake time.
//
// Every level the asset can be drawn at (Forest::getCandidateLevels: each technique's levels,
// the polygonal reference "mesh" among them) is drawn alone through a one-tree Forest, as the
// Forest draws it in a scene, at each screen height of ErrorCurveOptions::heightsPx and from
// each view (azimuths around the tree and one from above), and compared with the CPU ray-traced
// reference (ReferenceRenderer, supersampled) over a square crop around the tree (the union of
// the reference's and every level's tree pixels in that view, so the levels are judged over the
// same pixels): FLIP (Andersson et al. 2020) and multi-scale RMSE (the
// ellipsoids-and-lines paper, §4). The curves the selection reads (flip, rmse) average the views
// up to 60 degrees of elevation; the view from above counts in the worst view (flipMax) only: a
// crown thinned from above is not what a camera near the ground sees of it. The view is sized so the tree's box height spans `heightPx`
// pixels at the distance the Forest's LoD would see it at (the units of ForestBand).
// The "mesh" curve is the rasteriser's own error at that size: the floor no level can beat.
// The switch FLIP of two levels (switchFlip, what a hard switch between them shows) compares the
// two levels' images of the same views as flip with each other, over the pixels that are tree in
// either: no extra frame, each image filtered for FLIP once (FlipReference).
// The GPU bytes (resourceBytes) are read from the same one-tree Forests: each level's buffers and
// textures at every height (Forest::getGpuResources), each resource once.
//
// Deviation: a level is measured with its bark at full detail (a Forest draws a level's bark at
// the mesh LoD of the largest value the level is used at), so curves of coarse levels used near
// are exact and those used far are slightly pessimistic where their bark would have been coarser.
#pragma once

#include "TreeLod/ErrorCurves.h"
#include "TreeLod/Progress.h"
#include "TreeLod/Result.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace TreeLod
{
    class OffscreenRenderer;
    class TreeAsset;

    struct ErrorCurveOptions
    {
        std::vector<float> heightsPx{8.0f, 16.0f, 32.0f, 64.0f, 128.0f, 256.0f, 512.0f};
        /// (azimuth, elevation) in degrees: three around at 10 degrees, one at 45, one from above.
        std::vector<glm::vec2> views{{0.0f, 10.0f}, {120.0f, 10.0f}, {240.0f, 10.0f}, {60.0f, 45.0f}, {30.0f, 85.0f}};
        /// ErrorCurveLevel::flip and rmse average the views at this elevation or below (those a camera
        /// near the ground sees); flipMax is the worst of all of them, from above included. All
        /// views count when none is this low.
        float meanMaxElevation = 60.0f;
        int referenceSupersample = 2; ///< per axis
    };

    /// Measure the curves of every candidate level of `asset` (loaded) with `renderer`, under the
    /// default LightingSpec (the CPU reference's) without shadows; the renderer is left so. Error naming the asset and the level when a
    /// level cannot be drawn or the metrics fail.
    Result<ErrorCurves> measureErrorCurves(OffscreenRenderer& renderer, TreeAsset& asset,
                                           const ErrorCurveOptions& options = {}, const ProgressCallback& progress = {});

    /// Whether `curves` hold every candidate level of `asset` at the heights of `options`, with the
    /// switch FLIP between them and their GPU bytes (not so for curves of versions 1 and 2).
    bool coversCandidateLevels(const ErrorCurves& curves, TreeAsset& asset, const ErrorCurveOptions& options = {});

    /// The package `bytes` with its error-curves chunk measured and added (replaced), every other
    /// chunk copied unchanged. `label` names the package in errors.
    Result<std::vector<std::uint8_t>> addErrorCurves(OffscreenRenderer& renderer, const std::vector<std::uint8_t>& bytes,
                                                     const std::string& label, const ErrorCurveOptions& options = {},
                                                     const ProgressCallback& progress = {});

    /// Add the error-curves chunk to the package at `path` (all its other chunks copied unchanged),
    /// atomically, unless it holds curves that cover every candidate level already. Returns
    /// whether it measured. Errors name the package; the file is unchanged then.
    Result<bool> ensureErrorCurves(OffscreenRenderer& renderer, const std::string& path,
                                   const ErrorCurveOptions& options = {}, const ProgressCallback& progress = {});
}

// CaptureSet: the input of the volumetric octree tree (VolumeOctreeBaker.h): RGBA photographs whose
// alpha is the matte, with calibrated pinhole cameras, and the box the tree stands in (Reche-Martinez
// et al. 2004, as summarised by Linz et al. 2006, §2.1). A polygonal tree becomes a capture set by
// rendering it from N cameras with the CPU reference renderer (synthesiseCaptureSet); the
// reconstruction then reads those images exactly as it reads photographs.
//
// ---- Camera model ---------------------------------------------------------------------------
// worldToCamera maps world metres to camera space, OpenGL style: the camera looks down -z, +x is
// right and +y up in the image. A camera-space point (x, y, z) with z < 0 lands on the pixel
// coordinates
//     u = cx + fx * x / -z,   v = cy - fy * y / -z
// where u runs right and v down from the image's top-left corner, in pixels, so pixel (i, j)
// covers [i, i + 1) x [j, j + 1) and its centre is (i + 0.5, j + 0.5). For the reference renderer's
// perspective CameraSpec of vertical field of view f and a W x H image: fx = fy = H / (2 tan(f/2)),
// cx = W / 2, cy = H / 2 (captureCameraFromSpec).
//
// ---- Folder layout (readCaptureSet, writeCaptureSet) ----------------------------------------
//   <folder>/cameras.json
//     {"format": "treelod-capture", "version": 1,
//      "volume": {"min": [x, y, z], "max": [x, y, z]},          metres, min < max on every axis
//      "cameras": [{"name": "cam00", "image": "cam00.png",         a file in the folder
//                   "width": 256, "height": 256,                  the image's size, checked
//                   "fx": 309.0, "fy": 309.0, "cx": 128.0, "cy": 128.0,
//                   "worldToCamera": [16 numbers, row-major]},    last row 0 0 0 1
//                  ...]}
//   <folder>/<image>  RGBA PNG (8 or 16 bit), sRGB colour, straight (not premultiplied) alpha.
#pragma once

#include "TreeLod/Camera.h"
#include "TreeLod/Image.h"
#include "TreeLod/Progress.h"
#include "TreeLod/Result.h"
#include "TreeLod/TreeModel.h"

#include <glm/glm.hpp>

#include <string>
#include <vector>

namespace TreeLod
{
    constexpr const char* CAPTURE_SET_FILE = "cameras.json";
    constexpr int CAPTURE_SET_FORMAT_VERSION = 1;

    struct CaptureCamera
    {
        std::string name;      ///< unique in the set; errors name it
        std::string image;     ///< the image's file name in the folder
        int width = 0, height = 0;
        double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0; ///< pixels; fx, fy > 0
        glm::dmat4 worldToCamera{1.0};                  ///< rigid: rotation and translation only

        /// The camera's centre in world space.
        glm::dvec3 position() const;
        /// Unit world-space direction the camera looks along (camera -z).
        glm::dvec3 forward() const;
        /// Pixel coordinates (u, v) of a world point and its depth (metres along forward); false
        /// when the point is not in front of the camera (depth <= 1e-9 * scale).
        bool project(const glm::dvec3& world, glm::dvec2& pixel, double& depth) const;
        /// Unit world-space direction of the ray through pixel coordinates (u, v).
        glm::dvec3 rayDirection(const glm::dvec2& pixel) const;
    };

    struct CaptureSet
    {
        glm::dvec3 volumeMin{0.0}, volumeMax{0.0}; ///< the box that holds the tree
        std::vector<CaptureCamera> cameras;
        std::vector<Image> images; ///< one per camera, its width x height; sRGB, alpha = matte

        /// Checks with errors naming `label`, the camera ("camera 'cam03'") and the reason:
        /// no camera; a volume that is not a finite box with min < max; duplicate names; a non-finite
        /// or non-rigid worldToCamera (rotation not orthonormal within 1e-4, last row not 0 0 0 1);
        /// non-finite or non-positive fx, fy, non-finite cx, cy; an image whose size is not the
        /// camera's (or missing); non-finite pixel values; a camera that sees nothing of the volume
        /// (no corner of the box in front of it, or the box's projection misses the image).
        Result<void> validate(const std::string& label) const;
    };

    /// The CaptureCamera of a perspective CameraSpec rendering a width x height image (the
    /// conventions above). Orthographic specs are not capture cameras (std::invalid_argument).
    CaptureCamera captureCameraFromSpec(const CameraSpec& spec, int width, int height, const std::string& name);

    /// Read `<folder>/cameras.json` and every image, then validate(). Errors name the file
    /// (cameras.json or the image), the element ("camera 'cam03'", "volume", "cameras[2].fx") and
    /// the reason: missing or unreadable files, bad JSON, wrong format or version, missing or
    /// wrongly typed keys, an image whose size differs from the JSON's.
    Result<CaptureSet> readCaptureSet(const std::string& folder);

    /// Write the set to `folder` (created if missing): the images as 8-bit RGBA PNGs named by
    /// each camera's `image`, then cameras.json. Whole or nothing: everything is written to a
    /// temporary folder next to `folder` and renamed into place only when complete; an existing
    /// cameras.json in `folder` is an error (nothing is overwritten).
    Result<void> writeCaptureSet(const CaptureSet& set, const std::string& folder);

    struct CaptureSynthesisOptions
    {
        int cameraCount = 24;   ///< in [1, 256]: cameras on rings around the tree (see below)
        int resolution = 256;   ///< pixels a side of every image, in [16, 4096]
        int samplesPerPixel = 4; ///< reference renderer samples per pixel, a square in [1, 256]
        float fovYDegrees = 30.0f;
        /// Distance of the cameras from the volume's centre, in radii of the volume's bounding
        /// sphere; > 1 (the camera outside the box) unless insideCamera tests want otherwise.
        float distanceInRadii = 3.0f;
        LightingSpec lighting;  ///< the photographs' light (it stays baked in, as in the paper)
    };

    /// Render `model` from options.cameraCount cameras, all looking at the centre of its bounding
    /// box, placed deterministically: a ring of ceil(n / 2) cameras at elevation 10 degrees, a ring
    /// of the rest but one at 40 degrees offset by half a step in azimuth, and the last one at 75
    /// degrees (n = 1: one camera at elevation 10 degrees, azimuth 0; azimuth 0 is +z). Images are
    /// lit by options.lighting with a transparent background (alpha = coverage). The volume is the
    /// model's bounding box grown by 2 % on every side. Errors name `label`: invalid options,
    /// a model with no extent. Progress step: "capture: views".
    Result<CaptureSet> synthesiseCaptureSet(const TreeModel& model, const CaptureSynthesisOptions& options,
                                            const std::string& label, const ProgressCallback& progress = {});
}

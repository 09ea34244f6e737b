// CameraSpec: one camera description shared by the CPU reference renderer (core)
// and the Ogre renderer (plugin), so images of the same tree line up pixel for pixel.
// Right-handed, +Y up, looking from `position` at `target`, OpenGL clip conventions.
#pragma once

#include <glm/glm.hpp>

#include <cmath>
#include <string>

namespace TreeLod
{
    /// Distance at which a tree `treeHeight` metres tall is about `px` pixels tall in a
    /// `size`-pixel-high view with a vertical field of view of `fovYDegrees` (small-angle).
    inline double distanceForHeight(double treeHeight, double px, int size, double fovYDegrees = 45.0)
    {
        return treeHeight * size / (2.0 * px * std::tan(0.5 * fovYDegrees * 3.14159265358979323846 / 180.0));
    }

    struct CameraSpec
    {
        glm::vec3 position{0.0f, 1.0f, 10.0f};
        glm::vec3 target{0.0f, 1.0f, 0.0f};
        glm::vec3 up{0.0f, 1.0f, 0.0f};
        float fovYDegrees = 45.0f;    ///< perspective only
        bool orthographic = false;
        float orthoHeight = 10.0f;    ///< orthographic: height of the view in metres
        float nearClip = 0.05f;
        float farClip = 10000.0f;

        glm::mat4 viewMatrix() const;
        glm::mat4 projectionMatrix(float aspect) const; ///< aspect = width / height

        /// A camera that frames the box [lo, hi] seen from the given azimuth and elevation
        /// (degrees; azimuth 0 looks along -Z, i.e. from +Z) at `distanceFactor` times the
        /// distance at which the box's bounding sphere just fills the vertical field of view.
        static CameraSpec framing(const glm::vec3& lo, const glm::vec3& hi, float azimuthDegrees,
                                  float elevationDegrees, float distanceFactor = 1.0f,
                                  float fovYDegrees = 45.0f);

        /// Parse "px,py,pz,tx,ty,tz[,fov]" or "orbit:azimuth,elevation,distanceFactor" (the
        /// latter needs the bounds). Returns false and sets `error` on bad text.
        static bool parse(const std::string& text, const glm::vec3& lo, const glm::vec3& hi,
                          CameraSpec& out, std::string& error);
    };

    /// Shading shared by the CPU reference renderer and the GLSL materials:
    /// colour = albedo * (ambient * ao + sunColour * max(0, dot(n, sunDirection)))
    /// in linear space, written as sRGB. Leaves are two-sided: n faces the viewer, and the
    /// back side uses the material's back colour when it is set. Background is opaque.
    struct LightingSpec
    {
        glm::vec3 sunDirection = glm::normalize(glm::vec3(0.4f, 0.8f, 0.45f)); ///< towards the sun
        glm::vec3 sunColour{0.85f, 0.82f, 0.75f};
        glm::vec3 ambientColour{0.35f, 0.38f, 0.45f};
        glm::vec3 background{0.62f, 0.74f, 0.88f}; ///< sRGB clear colour
    };
}

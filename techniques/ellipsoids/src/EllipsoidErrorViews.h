// The views both ellipsoid bakers measure image error in (the ellipsoids-and-lines paper (001)
// §4; EllipsoidTreeBaker.h, EllipsoidLineBaker.h): four orthographic views of the sphere
// (centre, radius), three around at 15 degrees elevation and one from above, rendered by the CPU
// ReferenceRenderer in flat white on black (coverage only) or shaded, 2 x 2 samples a pixel.
#pragma once

#include "TreeLod/ReferenceRenderer.h"

#include <glm/glm.hpp>

#include <cmath>
#include <vector>

namespace TreeLod
{
    namespace EllipsoidErrorViews
    {
        constexpr int SAMPLES = 2; ///< per pixel per axis

        inline std::vector<CameraSpec> cameras(const glm::vec3& centre, float radius)
        {
            std::vector<CameraSpec> out;
            const float elevation = glm::radians(15.0f);
            for (int v = 0; v < 4; ++v)
            {
                CameraSpec c;
                c.orthographic = true;
                c.target = centre;
                glm::vec3 towards;
                if (v < 3)
                {
                    const float azimuth = glm::radians(120.0f * float(v));
                    towards = glm::vec3(std::sin(azimuth) * std::cos(elevation), std::sin(elevation),
                                        std::cos(azimuth) * std::cos(elevation));
                    c.up = glm::vec3(0, 1, 0);
                }
                else
                {
                    towards = glm::vec3(0, 1, 0);
                    c.up = glm::vec3(0, 0, -1);
                }
                c.position = centre + 3.0f * radius * towards;
                c.orthoHeight = 2.1f * radius;
                c.nearClip = 0.5f * radius;
                c.farClip = 6.0f * radius;
                out.push_back(c);
            }
            return out;
        }

        /// Shaded: white surfaces under RenderOptions' default sun and sky light, on black (the
        /// normal noise's calibration, EllipsoidTreeBaker.h).
        inline RenderOptions shadedRenderOptions(int resolution)
        {
            RenderOptions o;
            o.width = o.height = resolution;
            o.samplesPerPixel = SAMPLES * SAMPLES;
            o.lighting.background = glm::vec3(0.0f);
            return o;
        }

        inline RenderOptions renderOptions(int resolution)
        {
            RenderOptions o;
            o.width = o.height = resolution;
            o.samplesPerPixel = SAMPLES * SAMPLES;
            o.lighting.ambientColour = glm::vec3(1.0f);
            o.lighting.sunColour = glm::vec3(0.0f);
            o.lighting.background = glm::vec3(0.0f);
            return o;
        }
    }
}

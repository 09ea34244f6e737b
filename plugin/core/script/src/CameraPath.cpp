// The camera path: keyframes joined by centripetal Catmull-Rom splines (or straight lines).
//
// This work is based on:
//   P. J. Barry, R. N. Goldman, "A recursive evaluation algorithm for a class of Catmull-Rom
//   splines", SIGGRAPH 1988, with the centripetal knots of Yuksel, Schaefer, Keyser,
//   "Parameterization and applications of Catmull-Rom curves", CAD 43(7), 2011.
#include "TreeLod/SceneScript.h"

#include <algorithm>
#include <cmath>

namespace TreeLod
{
    namespace
    {
        /// Centripetal Catmull-Rom between p1 and p2 (s in [0, 1]), neighbours p0 and p3.
        glm::dvec3 catmullRom(glm::dvec3 p0, const glm::dvec3& p1, const glm::dvec3& p2, glm::dvec3 p3, double s)
        {
            const double d12 = glm::length(p2 - p1);
            if (d12 < 1e-9)
                return p1;
            // A neighbour on top of its end point (a held camera, a fixed target) would make a
            // zero knot interval: mirror the segment instead, as at the path's ends.
            if (glm::length(p1 - p0) < 1e-6 * d12)
                p0 = 2.0 * p1 - p2;
            if (glm::length(p3 - p2) < 1e-6 * d12)
                p3 = 2.0 * p2 - p1;
            const double t0 = 0.0;
            const double t1 = t0 + std::sqrt(glm::length(p1 - p0));
            const double t2 = t1 + std::sqrt(d12);
            const double t3 = t2 + std::sqrt(glm::length(p3 - p2));
            const double t = t1 + s * (t2 - t1);
            glm::dvec3 a1 = ((t1 - t) * p0 + (t - t0) * p1) / (t1 - t0);
            glm::dvec3 a2 = ((t2 - t) * p1 + (t - t1) * p2) / (t2 - t1);
            glm::dvec3 a3 = ((t3 - t) * p2 + (t - t2) * p3) / (t3 - t2);
            glm::dvec3 b1 = ((t2 - t) * a1 + (t - t0) * a2) / (t2 - t0);
            glm::dvec3 b2 = ((t3 - t) * a2 + (t - t1) * a3) / (t3 - t1);
            return ((t2 - t) * b1 + (t - t1) * b2) / (t2 - t1);
        }

        glm::vec3 interpolate(const SceneCamera& camera, std::size_t i, double s, bool target)
        {
            const std::vector<SceneKeyframe>& k = camera.keyframes;
            auto at = [&](std::size_t j) { return glm::dvec3(target ? k[j].target : k[j].position); };
            glm::dvec3 p1 = at(i), p2 = at(i + 1);
            if (s <= 0.0)
                return glm::vec3(p1);
            if (camera.linear)
                return glm::vec3(p1 + s * (p2 - p1));
            glm::dvec3 p0 = i > 0 ? at(i - 1) : 2.0 * p1 - p2;
            glm::dvec3 p3 = i + 2 < k.size() ? at(i + 2) : 2.0 * p2 - p1;
            return glm::vec3(catmullRom(p0, p1, p2, p3, s));
        }
    }

    CameraSpec cameraAt(const SceneScript& script, double time)
    {
        const SceneCamera& c = script.camera;
        CameraSpec spec;
        spec.fovYDegrees = c.fovYDegrees;
        spec.nearClip = c.nearClip;
        spec.farClip = c.farClip;
        if (c.keyframes.empty())
            return spec;
        const std::vector<SceneKeyframe>& k = c.keyframes;
        if (k.size() == 1 || time <= k.front().time)
        {
            spec.position = k.front().position;
            spec.target = k.front().target;
            return spec;
        }
        if (time >= k.back().time)
        {
            spec.position = k.back().position;
            spec.target = k.back().target;
            return spec;
        }
        // Segment i with k[i].time <= time < k[i + 1].time.
        std::size_t i = std::size_t(std::upper_bound(k.begin(), k.end(), time,
                                                     [](double t, const SceneKeyframe& f) { return t < f.time; }) -
                                    k.begin()) - 1;
        double s = (time - k[i].time) / (k[i + 1].time - k[i].time);
        spec.position = interpolate(c, i, s, false);
        spec.target = interpolate(c, i, s, true);
        return spec;
    }

    double frameTime(const SceneScript& script, std::uint32_t frame, std::uint32_t frameCount)
    {
        const std::vector<SceneKeyframe>& k = script.camera.keyframes;
        if (k.empty())
            return 0.0;
        std::uint32_t n = frameCount ? frameCount : script.frames;
        if (n <= 1)
            return k.front().time;
        frame = std::min(frame, n - 1);
        return k.front().time + (k.back().time - k.front().time) * double(frame) / double(n - 1);
    }
}

#include "TreeLod/Camera.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

namespace TreeLod
{
    glm::mat4 CameraSpec::viewMatrix() const { return glm::lookAt(position, target, up); }

    glm::mat4 CameraSpec::projectionMatrix(float aspect) const
    {
        if (orthographic)
        {
            float h = 0.5f * orthoHeight, w = h * aspect;
            return glm::ortho(-w, w, -h, h, nearClip, farClip);
        }
        return glm::perspective(glm::radians(fovYDegrees), aspect, nearClip, farClip);
    }

    CameraSpec CameraSpec::framing(const glm::vec3& lo, const glm::vec3& hi, float azimuthDegrees,
                                   float elevationDegrees, float distanceFactor, float fovYDegrees)
    {
        CameraSpec cam;
        glm::vec3 centre = 0.5f * (lo + hi);
        float radius = std::max(0.5f * glm::length(hi - lo), 1e-3f);
        float dist = radius / std::sin(glm::radians(0.5f * fovYDegrees)) * distanceFactor;
        float az = glm::radians(azimuthDegrees), el = glm::radians(elevationDegrees);
        glm::vec3 dir(std::sin(az) * std::cos(el), std::sin(el), std::cos(az) * std::cos(el));
        cam.target = centre;
        cam.position = centre + dir * dist;
        cam.fovYDegrees = fovYDegrees;
        cam.nearClip = std::max(dist - radius * 1.5f, dist * 1e-3f);
        cam.farClip = dist + radius * 1.5f;
        cam.orthoHeight = 2.0f * radius;
        return cam;
    }

    bool CameraSpec::parse(const std::string& text, const glm::vec3& lo, const glm::vec3& hi, CameraSpec& out,
                           std::string& error)
    {
        std::string body = text;
        bool orbit = false, ortho = false;
        for (const char* prefix : {"orbit:", "ortho:"})
            if (body.rfind(prefix, 0) == 0)
            {
                orbit = true;
                ortho = std::string(prefix) == "ortho:";
                body = body.substr(6);
            }
        std::vector<float> v;
        std::stringstream ss(body);
        std::string item;
        while (std::getline(ss, item, ','))
        {
            try
            {
                std::size_t used = 0;
                v.push_back(std::stof(item, &used));
                if (used != item.size())
                    throw std::invalid_argument(item);
            }
            catch (const std::exception&)
            {
                error = "camera '" + text + "': '" + item + "' is not a number";
                return false;
            }
        }
        for (float f : v)
            if (!std::isfinite(f))
            {
                error = "camera '" + text + "': values must be finite";
                return false;
            }
        if (orbit)
        {
            if (v.size() != 3 || v[2] <= 0.0f)
            {
                error = "camera '" + text + "': expected orbit:azimuth,elevation,distanceFactor with distanceFactor > 0";
                return false;
            }
            out = framing(lo, hi, v[0], v[1], v[2]);
            out.orthographic = ortho;
            return true;
        }
        if (v.size() != 6 && v.size() != 7)
        {
            error = "camera '" + text + "': expected px,py,pz,tx,ty,tz[,fov] or orbit:az,el,dist";
            return false;
        }
        CameraSpec cam;
        cam.position = {v[0], v[1], v[2]};
        cam.target = {v[3], v[4], v[5]};
        if (v.size() == 7)
            cam.fovYDegrees = v[6];
        if (glm::length(cam.target - cam.position) <= 0.0f || cam.fovYDegrees <= 0.0f || cam.fovYDegrees >= 180.0f)
        {
            error = "camera '" + text + "': position equals target or fov outside (0, 180)";
            return false;
        }
        float radius = std::max(0.5f * glm::length(hi - lo), 1e-3f);
        float farthest = glm::length(cam.position - 0.5f * (lo + hi)) + radius * 1.5f;
        cam.nearClip = std::max(1e-3f, farthest * 1e-5f);
        cam.farClip = farthest;
        out = cam;
        return true;
    }
}

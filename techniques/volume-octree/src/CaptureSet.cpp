// CaptureSet: calibrated RGBA views of a tree (the volumetric octree's input): the pinhole camera
// model, validation, the cameras.json folder (read, whole-or-nothing write) and views synthesised
// from a TreeModel with the reference renderer.
#include "TreeLod/CaptureSet.h"

#include "TreeLod/AtomicFile.h"
#include "TreeLod/ReferenceRenderer.h"

#include <nlohmann/json.hpp>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <stdexcept>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace TreeLod
{
    namespace
    {
        namespace fs = std::filesystem;
        using Json = nlohmann::json;

        constexpr const char* FORMAT_NAME = "treelod-capture";
        constexpr double PI = 3.14159265358979323846;

        std::string cameraElement(const CaptureCamera& camera, std::size_t index)
        {
            return camera.name.empty() ? "cameras[" + std::to_string(index) + "]" : "camera '" + camera.name + "'";
        }

        std::string sizeText(int width, int height) { return std::to_string(width) + "x" + std::to_string(height); }

        std::string numberText(double v)
        {
            char text[32];
            std::snprintf(text, sizeof(text), "%g", v);
            return text;
        }

        std::string vecText(const glm::dvec3& v)
        {
            char text[96];
            std::snprintf(text, sizeof(text), "(%g, %g, %g)", v.x, v.y, v.z);
            return text;
        }

        bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

        /// A plain file name: no folder part, not "." or "..".
        bool plainFileName(const std::string& name)
        {
            return !name.empty() && name != "." && name != ".." && name.find('/') == std::string::npos &&
                   name.find('\\') == std::string::npos && name.find('\0') == std::string::npos;
        }

        // ---- seeing the volume -----------------------------------------------------------------

        double cross2(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& p)
        {
            return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
        }

        /// Convex hull, counter-clockwise in (u, v) axes, collinear points dropped (Andrew's chain).
        std::vector<glm::dvec2> convexHull(std::vector<glm::dvec2> points)
        {
            std::sort(points.begin(), points.end(),
                      [](const glm::dvec2& a, const glm::dvec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
            if (points.size() < 3)
                return points;
            std::vector<glm::dvec2> hull(2 * points.size());
            std::size_t k = 0;
            for (std::size_t i = 0; i < points.size(); ++i)
            {
                while (k >= 2 && cross2(hull[k - 2], hull[k - 1], points[i]) <= 0.0)
                    --k;
                hull[k++] = points[i];
            }
            for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;)
            {
                while (k >= lower && cross2(hull[k - 2], hull[k - 1], points[i]) <= 0.0)
                    --k;
                hull[k++] = points[i];
            }
            hull.resize(k - 1);
            return hull;
        }

        enum class BoxView
        {
            Seen,
            Behind,  ///< no corner in front of the camera
            Outside, ///< in front, but its projection misses the image
        };

        /// Whether the box [lo, hi] shows in the camera's image: the box cut at a plane just in
        /// front of the camera, projected; its convex outline is tested against the image rectangle
        /// (separating axes: the rectangle's and the outline's edges).
        BoxView viewOfBox(const CaptureCamera& camera, const glm::dvec3& lo, const glm::dvec3& hi)
        {
            glm::dvec3 corners[8];
            double scale = 1.0;
            for (int c = 0; c < 8; ++c)
            {
                const glm::dvec3 world((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z);
                corners[c] = glm::dvec3(camera.worldToCamera * glm::dvec4(world, 1.0));
                scale = std::max({scale, std::abs(corners[c].x), std::abs(corners[c].y), std::abs(corners[c].z)});
            }
            const double cut = -1e-9 * scale; // camera-space z of the cutting plane
            std::vector<glm::dvec3> front;
            for (int c = 0; c < 8; ++c)
            {
                if (corners[c].z < cut)
                    front.push_back(corners[c]);
                for (int axis = 1; axis < 8; axis <<= 1) // each edge once, from its lower corner
                {
                    if (c & axis)
                        continue;
                    const glm::dvec3& a = corners[c];
                    const glm::dvec3& b = corners[c | axis];
                    if ((a.z < cut) != (b.z < cut))
                        front.push_back(a + (b - a) * ((cut - a.z) / (b.z - a.z)));
                }
            }
            if (front.empty())
                return BoxView::Behind;

            std::vector<glm::dvec2> points;
            glm::dvec2 lowest(INFINITY), highest(-INFINITY);
            for (const glm::dvec3& p : front)
            {
                const glm::dvec2 uv(camera.cx + camera.fx * p.x / -p.z, camera.cy - camera.fy * p.y / -p.z);
                points.push_back(uv);
                lowest = glm::min(lowest, uv);
                highest = glm::max(highest, uv);
            }
            if (highest.x <= 0.0 || highest.y <= 0.0 || lowest.x >= camera.width || lowest.y >= camera.height)
                return BoxView::Outside;
            // Counter-clockwise in (u, v): the outside of edge a -> b is where cross2 < 0.
            const std::vector<glm::dvec2> hull = convexHull(points);
            const glm::dvec2 rect[4] = {{0.0, 0.0}, {double(camera.width), 0.0},
                                        {double(camera.width), double(camera.height)}, {0.0, double(camera.height)}};
            for (std::size_t i = 0; hull.size() >= 3 && i < hull.size(); ++i)
            {
                const glm::dvec2& a = hull[i];
                const glm::dvec2& b = hull[(i + 1) % hull.size()];
                auto outside = [&](const glm::dvec2& p) { return cross2(a, b, p) <= 0.0; };
                if (std::all_of(std::begin(rect), std::end(rect), outside))
                    return BoxView::Outside;
            }
            return BoxView::Seen;
        }

        // ---- cameras.json reading --------------------------------------------------------------

        /// Internal only: thrown by the readers below, turned into a Result at the top.
        struct JsonError
        {
            std::string element;
            std::string reason;
        };

        [[noreturn]] void bad(const std::string& element, const std::string& reason)
        {
            throw JsonError{element, reason};
        }

        std::string child(const std::string& element, const std::string& key)
        {
            return element.empty() ? key : element + "." + key;
        }

        std::string child(const std::string& element, std::size_t index)
        {
            return element + "[" + std::to_string(index) + "]";
        }

        const Json& need(const Json& object, const std::string& element, const std::string& key)
        {
            auto it = object.find(key);
            if (it == object.end())
                bad(child(element, key), "missing (a required key)");
            return *it;
        }

        void expectObject(const Json& v, const std::string& element)
        {
            if (!v.is_object())
                bad(element, std::string("must be an object, not ") + v.type_name());
        }

        void expectArray(const Json& v, const std::string& element, std::size_t size)
        {
            if (!v.is_array() || v.size() != size)
                bad(element, "must be an array of " + std::to_string(size) + " numbers");
        }

        double number(const Json& v, const std::string& element)
        {
            if (v.is_null())
                bad(element, "must be a number, not null (NaN and infinity are written as null)");
            if (!v.is_number())
                bad(element, std::string("must be a number, not ") + v.type_name());
            return v.get<double>();
        }

        int positiveInteger(const Json& v, const std::string& element)
        {
            if (!v.is_number_integer() || v.get<std::int64_t>() <= 0 || v.get<std::int64_t>() > 1000000)
                bad(element, "must be a whole number of pixels in [1, 1000000]");
            return int(v.get<std::int64_t>());
        }

        std::string text(const Json& v, const std::string& element)
        {
            if (!v.is_string())
                bad(element, std::string("must be a string, not ") + v.type_name());
            return v.get<std::string>();
        }

        glm::dvec3 vec3(const Json& v, const std::string& element)
        {
            expectArray(v, element, 3);
            return {number(v[0], child(element, 0)), number(v[1], child(element, 1)), number(v[2], child(element, 2))};
        }

        CaptureCamera readCamera(const Json& j, const std::string& element)
        {
            expectObject(j, element);
            CaptureCamera camera;
            camera.name = text(need(j, element, "name"), child(element, "name"));
            if (camera.name.empty())
                bad(child(element, "name"), "must not be empty (errors and the views are named by it)");
            camera.image = text(need(j, element, "image"), child(element, "image"));
            if (!plainFileName(camera.image))
                bad(child(element, "image"), "'" + camera.image + "' is not the name of a file in the folder");
            camera.width = positiveInteger(need(j, element, "width"), child(element, "width"));
            camera.height = positiveInteger(need(j, element, "height"), child(element, "height"));
            camera.fx = number(need(j, element, "fx"), child(element, "fx"));
            camera.fy = number(need(j, element, "fy"), child(element, "fy"));
            camera.cx = number(need(j, element, "cx"), child(element, "cx"));
            camera.cy = number(need(j, element, "cy"), child(element, "cy"));
            const std::string matrixElement = child(element, "worldToCamera");
            const Json& matrix = need(j, element, "worldToCamera");
            if (!matrix.is_array() || matrix.size() != 16)
                bad(matrixElement, "must be an array of 16 numbers (a 4x4 matrix, row-major)");
            for (std::size_t i = 0; i < 16; ++i)
                camera.worldToCamera[int(i % 4)][int(i / 4)] = number(matrix[i], child(matrixElement, i));
            return camera;
        }

        /// "line L, column C" of byte `offset` in `text`.
        std::string lineColumn(const std::string& text, std::size_t offset)
        {
            offset = std::min(offset, text.size());
            std::size_t line = 1, column = 1;
            for (std::size_t i = 0; i < offset; ++i)
            {
                if (text[i] == '\n')
                {
                    ++line;
                    column = 1;
                }
                else
                    ++column;
            }
            return "line " + std::to_string(line) + ", column " + std::to_string(column);
        }

        // ---- whole-or-nothing folder -----------------------------------------------------------

        std::string osError(const std::string& what, int error) { return what + ": " + std::strerror(error); }

        /// Flushes directory `dir` so that renames in it survive a crash (EINVAL: cannot be synced).
        Result<void> syncDirectory(const std::string& file, const fs::path& dir)
        {
            const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
            if (fd < 0)
                return fail(file, "", osError("written, but its folder cannot be opened to sync it", errno));
            const bool synced = ::fsync(fd) == 0 || errno == EINVAL;
            const int error = errno;
            ::close(fd);
            if (!synced)
                return fail(file, "", osError("written, but its folder cannot be synced", error));
            return {};
        }

        /// A new, empty folder beside `target` whose name holds the process id and a counter.
        Result<fs::path> createTempFolder(const std::string& file, const fs::path& target)
        {
            static std::atomic<unsigned long long> counter{0};
            for (int attempt = 0; attempt < 100; ++attempt)
            {
                char suffix[48];
                std::snprintf(suffix, sizeof(suffix), ".tmp%ld-%llu", long(getpid()), counter++);
                const fs::path temp = target.parent_path() / ("." + target.filename().string() + suffix);
                if (::mkdir(temp.c_str(), 0777) == 0)
                    return temp;
                if (errno != EEXIST)
                    return fail(file, "", osError("cannot create a temporary folder beside '" + target.string() + "'",
                                                  errno));
            }
            return fail(file, "", "cannot create a temporary folder beside '" + target.string() +
                                      "': every name tried exists");
        }

        /// The files of `temp` moved into the existing folder `target`, cameras.json last; on a
        /// failure the images already moved are removed again.
        Result<void> moveFilesInto(const fs::path& temp, const fs::path& target, const std::vector<std::string>& images)
        {
            std::vector<std::string> order = images;
            order.push_back(CAPTURE_SET_FILE);
            std::error_code ec;
            for (std::size_t i = 0; i < order.size(); ++i)
            {
                const fs::path to = target / order[i];
                const bool taken = fs::exists(fs::symlink_status(to, ec));
                if (taken || ::rename((temp / order[i]).c_str(), to.c_str()) != 0)
                {
                    const int error = taken ? EEXIST : errno;
                    for (std::size_t k = 0; k < i; ++k)
                        fs::remove(target / order[k], ec);
                    return fail(to.string(), "", osError("cannot move the new file into place", error));
                }
            }
            return {};
        }

        // ---- synthesis -------------------------------------------------------------------------

        /// Unit direction from the target towards a camera at `azimuth` (0 = +z, 90 = +x) and
        /// `elevation`, degrees.
        glm::dvec3 orbitDirection(double azimuthDegrees, double elevationDegrees)
        {
            const double az = azimuthDegrees * PI / 180.0, el = elevationDegrees * PI / 180.0;
            return {std::sin(az) * std::cos(el), std::sin(el), std::cos(az) * std::cos(el)};
        }

        /// (azimuth, elevation) in degrees of camera k of n (CaptureSet.h's placement).
        glm::dvec2 cameraPlacement(int k, int n)
        {
            if (n == 1)
                return {0.0, 10.0};
            const int lowRing = (n + 1) / 2, highRing = n - lowRing - 1;
            if (k < lowRing)
                return {360.0 * k / lowRing, 10.0};
            if (k < lowRing + highRing)
                return {360.0 * (k - lowRing + 0.5) / highRing, 40.0};
            return {0.0, 75.0};
        }

        std::string optionError(const char* name) { return std::string("capture option '") + name + "'"; }
    }

    // ---- CaptureCamera ---------------------------------------------------------------------------

    glm::dvec3 CaptureCamera::position() const { return glm::dvec3(glm::inverse(worldToCamera)[3]); }

    glm::dvec3 CaptureCamera::forward() const
    {
        return glm::normalize(glm::dvec3(glm::inverse(worldToCamera) * glm::dvec4(0.0, 0.0, -1.0, 0.0)));
    }

    bool CaptureCamera::project(const glm::dvec3& world, glm::dvec2& pixel, double& depth) const
    {
        const glm::dvec3 c(worldToCamera * glm::dvec4(world, 1.0));
        depth = -c.z;
        // scale: the point's distance from the camera, at least 1 m.
        if (!(depth > 1e-9 * std::max(1.0, glm::length(c))))
            return false;
        pixel = glm::dvec2(cx + fx * c.x / depth, cy - fy * c.y / depth);
        return true;
    }

    glm::dvec3 CaptureCamera::rayDirection(const glm::dvec2& pixel) const
    {
        const glm::dvec3 local((pixel.x - cx) / fx, -(pixel.y - cy) / fy, -1.0);
        return glm::normalize(glm::dvec3(glm::inverse(worldToCamera) * glm::dvec4(local, 0.0)));
    }

    // ---- CaptureSet ------------------------------------------------------------------------------

    Result<void> CaptureSet::validate(const std::string& label) const
    {
        if (cameras.empty())
            return fail(label, "cameras", "no camera: a capture set needs at least one view");
        if (!finite(volumeMin) || !finite(volumeMax) || !(volumeMin.x < volumeMax.x) || !(volumeMin.y < volumeMax.y) ||
            !(volumeMin.z < volumeMax.z))
            return fail(label, "volume", "min " + vecText(volumeMin) + " and max " + vecText(volumeMax) +
                                             " are not a box: they must be finite with min < max on every axis");
        if (images.size() != cameras.size())
            return fail(label, "images", std::to_string(images.size()) + " images for " +
                                             std::to_string(cameras.size()) + " cameras (one per camera)");

        std::map<std::string, std::size_t> names;
        for (std::size_t i = 0; i < cameras.size(); ++i)
        {
            const CaptureCamera& c = cameras[i];
            const std::string element = cameraElement(c, i);
            if (c.name.empty())
                return fail(label, element, "has no name (errors and the views are named by it)");
            auto [it, added] = names.emplace(c.name, i);
            if (!added)
                return fail(label, element, "the name is used by cameras[" + std::to_string(it->second) +
                                                "] and cameras[" + std::to_string(i) + "]: names must be unique");

            for (int column = 0; column < 4; ++column)
                for (int row = 0; row < 4; ++row)
                    if (!std::isfinite(c.worldToCamera[column][row]))
                        return fail(label, element, "worldToCamera row " + std::to_string(row) + " column " +
                                                        std::to_string(column) + " is not finite (NaN or infinity)");
            const glm::dmat4& m = c.worldToCamera;
            if (m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 || m[3][3] != 1.0)
                return fail(label, element, "worldToCamera's last row must be 0 0 0 1 (a rigid transform)");
            const glm::dmat3 r(m);
            const glm::dmat3 gram = glm::transpose(r) * r;
            double worst = 0.0;
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b)
                    worst = std::max(worst, std::abs(gram[a][b] - (a == b ? 1.0 : 0.0)));
            if (worst > 1e-4)
                return fail(label, element, "worldToCamera is not rigid: its rotation is not orthonormal (off by " +
                                                numberText(worst) + "; scale and shear are not allowed)");
            if (glm::determinant(r) < 0.0)
                return fail(label, element, "worldToCamera is not rigid: it mirrors (determinant -1)");

            if (!std::isfinite(c.fx) || !std::isfinite(c.fy) || !(c.fx > 0.0) || !(c.fy > 0.0))
                return fail(label, element, "focal lengths fx " + numberText(c.fx) + " and fy " +
                                                numberText(c.fy) + " must be finite and positive (pixels)");
            if (!std::isfinite(c.cx) || !std::isfinite(c.cy))
                return fail(label, element, "principal point cx, cy must be finite");
            if (c.width <= 0 || c.height <= 0)
                return fail(label, element, "image size " + sizeText(c.width, c.height) + " must be positive");

            const Image& image = images[i];
            if (image.empty())
                return fail(label, element, "no image");
            if (image.width != c.width || image.height != c.height ||
                image.pixels.size() != std::size_t(image.width) * image.height)
                return fail(label, element, "the image is " + sizeText(image.width, image.height) +
                                                " pixels, the camera's is " + sizeText(c.width, c.height));
            for (std::size_t p = 0; p < image.pixels.size(); ++p)
            {
                const glm::vec4& v = image.pixels[p];
                if (!std::isfinite(v.r) || !std::isfinite(v.g) || !std::isfinite(v.b) || !std::isfinite(v.a))
                    return fail(label, element, "pixel (" + std::to_string(p % std::size_t(image.width)) + ", " +
                                                    std::to_string(p / std::size_t(image.width)) + ") is not finite");
            }

            switch (viewOfBox(c, volumeMin, volumeMax))
            {
            case BoxView::Behind:
                return fail(label, element, "sees nothing of the volume: the whole box is behind the camera "
                                            "(is it looking away from the tree?)");
            case BoxView::Outside:
                return fail(label, element, "sees nothing of the volume: the box projects outside the image "
                                            "(check worldToCamera, fx, fy, cx, cy and the volume)");
            case BoxView::Seen:
                break;
            }
        }
        return {};
    }

    CaptureCamera captureCameraFromSpec(const CameraSpec& spec, int width, int height, const std::string& name)
    {
        if (spec.orthographic)
            throw std::invalid_argument("captureCameraFromSpec: camera '" + name +
                                        "' is orthographic; capture cameras are perspective");
        CaptureCamera camera;
        camera.name = name;
        camera.image = name + ".png";
        camera.width = width;
        camera.height = height;
        camera.fx = camera.fy = height / (2.0 * std::tan(0.5 * double(spec.fovYDegrees) * PI / 180.0));
        camera.cx = 0.5 * width;
        camera.cy = 0.5 * height;
        camera.worldToCamera = glm::lookAt(glm::dvec3(spec.position), glm::dvec3(spec.target), glm::dvec3(spec.up));
        return camera;
    }

    // ---- folder I/O ------------------------------------------------------------------------------

    Result<CaptureSet> readCaptureSet(const std::string& folder)
    {
        const std::string file = (fs::path(folder) / CAPTURE_SET_FILE).string();
        std::error_code ec;
        if (!fs::is_directory(folder, ec))
            return fail(folder, "", std::string(fs::exists(folder, ec) ? "is not a folder" : "folder does not exist") +
                                        " (a capture set is a folder with cameras.json and the images)");
        if (!fs::exists(file, ec))
            return fail(file, "", "file does not exist: a capture set folder holds cameras.json and the images");
        Result<std::vector<std::uint8_t>> bytes = readFile(file);
        if (!bytes)
            return bytes.error();
        const std::string content(bytes->begin(), bytes->end());

        Json root;
        try
        {
            root = Json::parse(content);
        }
        catch (const Json::parse_error& e)
        {
            // e.byte: 1-based index of the last character read (where the error shows).
            std::string what = e.what();
            const std::size_t column = what.find("column ");
            const std::size_t at = column == std::string::npos ? what.find("] ") : what.find(": ", column);
            return fail(file, lineColumn(content, e.byte > 0 ? e.byte - 1 : 0),
                        "not valid JSON: " + (at == std::string::npos ? what : what.substr(at + 2)));
        }
        catch (const Json::exception& e)
        {
            // A number beyond a double: "[json.exception.out_of_range.406] number overflow parsing '1e999'".
            const std::string what = e.what();
            const std::size_t at = what.find("] ");
            return fail(file, "", "not valid JSON: " + (at == std::string::npos ? what : what.substr(at + 2)) +
                                      " (beyond the range of a double)");
        }

        CaptureSet set;
        try
        {
            expectObject(root, "cameras.json");
            const Json& format = need(root, "", "format");
            if (!format.is_string() || format.get<std::string>() != FORMAT_NAME)
                bad("format", "is " + format.dump() + ", not \"" + FORMAT_NAME + "\": not a TreeLod capture set");
            const Json& version = need(root, "", "version");
            const std::string supported = "this build reads version " + std::to_string(CAPTURE_SET_FORMAT_VERSION);
            if (!version.is_number_integer())
                bad("version",
                    std::string("must be a whole number, not ") + version.type_name() + " (" + supported + ")");
            if (version.get<std::int64_t>() != CAPTURE_SET_FORMAT_VERSION)
                bad("version", "version " + version.dump() + " is not supported: " + supported);
            const Json& volume = need(root, "", "volume");
            expectObject(volume, "volume");
            set.volumeMin = vec3(need(volume, "volume", "min"), "volume.min");
            set.volumeMax = vec3(need(volume, "volume", "max"), "volume.max");
            const Json& cameras = need(root, "", "cameras");
            if (!cameras.is_array())
                bad("cameras", std::string("must be an array of cameras, not ") + cameras.type_name());
            for (std::size_t i = 0; i < cameras.size(); ++i)
                set.cameras.push_back(readCamera(cameras[i], child("cameras", i)));
        }
        catch (const JsonError& e)
        {
            return fail(file, e.element, e.reason);
        }

        for (std::size_t i = 0; i < set.cameras.size(); ++i)
        {
            const CaptureCamera& camera = set.cameras[i];
            const std::string path = (fs::path(folder) / camera.image).string();
            Result<Image> image = readImage(path);
            if (!image)
                return fail(path, cameraElement(camera, i), image.error().reason);
            if (image->width != camera.width || image->height != camera.height)
                return fail(path, cameraElement(camera, i),
                            "the image is " + sizeText(image->width, image->height) +
                                " pixels, but cameras.json says " + sizeText(camera.width, camera.height));
            set.images.push_back(std::move(image).value());
        }

        Result<void> valid = set.validate(file);
        if (!valid)
            return valid.error();
        return set;
    }

    Result<void> writeCaptureSet(const CaptureSet& set, const std::string& folder)
    {
        const std::string file = (fs::path(folder) / CAPTURE_SET_FILE).string();
        Result<void> valid = set.validate(file);
        if (!valid)
            return valid.error();

        std::map<std::string, std::size_t> imageNames;
        for (std::size_t i = 0; i < set.cameras.size(); ++i)
        {
            const std::string& image = set.cameras[i].image;
            std::string extension = fs::path(image).extension().string();
            std::transform(extension.begin(), extension.end(), extension.begin(),
                           [](unsigned char c) { return char(std::tolower(c)); });
            if (!plainFileName(image) || extension != ".png" || image == CAPTURE_SET_FILE)
                return fail(file, cameraElement(set.cameras[i], i),
                            "image '" + image + "' must be a file name ending in .png (written as PNG in the folder)");
            auto [it, added] = imageNames.emplace(image, i);
            if (!added)
                return fail(file, cameraElement(set.cameras[i], i),
                            "image '" + image + "' is also cameras[" + std::to_string(it->second) + "]'s");
        }

        std::error_code ec;
        fs::path target = fs::absolute(fs::path(folder), ec).lexically_normal();
        if (!target.has_filename())
            target = target.parent_path();
        if (ec || target.filename().empty() || target == target.root_path())
            return fail(folder, "", "cannot write a capture set here: not a folder name");
        const bool targetExists = fs::exists(fs::symlink_status(target, ec));
        if (targetExists && !fs::is_directory(target, ec))
            return fail(folder, "", "exists and is not a folder");
        if (targetExists)
        {
            if (fs::exists(fs::symlink_status(target / CAPTURE_SET_FILE, ec)))
                return fail(file, "", "already exists: a capture set is never overwritten (remove it or choose "
                                      "another folder)");
            for (const auto& [image, index] : imageNames)
                if (fs::exists(fs::symlink_status(target / image, ec)))
                    return fail((fs::path(folder) / image).string(), cameraElement(set.cameras[index], index),
                                "already exists: the capture set would overwrite it");
        }
        if (!fs::is_directory(target.parent_path(), ec) && !fs::create_directories(target.parent_path(), ec))
            return fail(folder, "", "cannot create its parent folder: " + ec.message());

        Result<fs::path> temp = createTempFolder(file, target);
        if (!temp)
            return temp.error();
        Result<void> result = [&]() -> Result<void> {
            for (std::size_t i = 0; i < set.cameras.size(); ++i)
            {
                Result<void> written = writePng((temp.value() / set.cameras[i].image).string(), set.images[i]);
                if (!written)
                    return fail((fs::path(folder) / set.cameras[i].image).string(), cameraElement(set.cameras[i], i),
                                written.error().reason);
            }
            nlohmann::ordered_json cameras = nlohmann::ordered_json::array();
            for (const CaptureCamera& c : set.cameras)
            {
                std::vector<double> matrix;
                for (int row = 0; row < 4; ++row)
                    for (int column = 0; column < 4; ++column)
                        matrix.push_back(c.worldToCamera[column][row]);
                cameras.push_back({{"name", c.name}, {"image", c.image}, {"width", c.width}, {"height", c.height},
                                   {"fx", c.fx}, {"fy", c.fy}, {"cx", c.cx}, {"cy", c.cy},
                                   {"worldToCamera", matrix}});
            }
            const nlohmann::ordered_json root = {
                {"format", FORMAT_NAME},
                {"version", CAPTURE_SET_FORMAT_VERSION},
                {"volume",
                 {{"min", {set.volumeMin.x, set.volumeMin.y, set.volumeMin.z}},
                  {"max", {set.volumeMax.x, set.volumeMax.y, set.volumeMax.z}}}},
                {"cameras", cameras}};
            const std::string text = root.dump(2) + "\n";
            Result<void> written = writeFileAtomic((temp.value() / CAPTURE_SET_FILE).string(),
                                                   std::vector<std::uint8_t>(text.begin(), text.end()));
            if (!written)
                return fail(file, "", written.error().reason);

            // A missing or empty folder is replaced whole; files are moved into one that has others.
            if (::rename(temp->c_str(), target.c_str()) == 0)
                return syncDirectory(file, target.parent_path());
            if (errno != EEXIST && errno != ENOTEMPTY && errno != ENOTDIR)
                return fail(file, "", osError("cannot rename the temporary folder into place", errno));
            std::vector<std::string> images;
            for (const CaptureCamera& c : set.cameras)
                images.push_back(c.image);
            Result<void> moved = moveFilesInto(temp.value(), target, images);
            if (!moved)
                return moved;
            return syncDirectory(file, target);
        }();
        fs::remove_all(temp.value(), ec); // gone already when renamed whole
        return result;
    }

    // ---- synthesis -------------------------------------------------------------------------------

    Result<CaptureSet> synthesiseCaptureSet(const TreeModel& model, const CaptureSynthesisOptions& options,
                                            const std::string& label, const ProgressCallback& progress)
    {
        if (options.cameraCount < 1 || options.cameraCount > 256)
            return fail(label, optionError("cameraCount"),
                        std::to_string(options.cameraCount) + " is not in [1, 256]");
        if (options.resolution < 16 || options.resolution > 4096)
            return fail(label, optionError("resolution"), std::to_string(options.resolution) + " is not in [16, 4096]");
        const int side = int(std::lround(std::sqrt(double(std::max(options.samplesPerPixel, 0)))));
        if (options.samplesPerPixel < 1 || options.samplesPerPixel > 256 || side * side != options.samplesPerPixel)
            return fail(label, optionError("samplesPerPixel"),
                        std::to_string(options.samplesPerPixel) + " is not a square in [1, 256] (1, 4, 9, 16 ...)");
        if (!std::isfinite(options.fovYDegrees) || !(options.fovYDegrees > 0.0f) || !(options.fovYDegrees < 180.0f))
            return fail(label, optionError("fovYDegrees"), numberText(options.fovYDegrees) +
                                                               " is not a field of view in (0, 180) degrees");
        if (!std::isfinite(options.distanceInRadii) || !(options.distanceInRadii > 0.0f))
            return fail(label, optionError("distanceInRadii"),
                        numberText(options.distanceInRadii) + " must be a positive distance (radii of the volume)");
        Result<void> valid = model.validate(label);
        if (!valid)
            return valid.error();

        glm::dvec3 lo(INFINITY), hi(-INFINITY);
        for (const std::vector<Vertex>* vertices : {&model.barkVertices, &model.leafVertices})
            for (const Vertex& v : *vertices)
            {
                lo = glm::min(lo, glm::dvec3(v.position));
                hi = glm::max(hi, glm::dvec3(v.position));
            }
        const double largest = hi.x >= lo.x ? std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z}) : 0.0;
        if (!(largest > 0.0))
            return fail(label, "model", "has no extent (no vertices, or all at one point): nothing to capture");

        // 2 % of the box's largest side on every side, so that a flat model still has a volume.
        CaptureSet set;
        set.volumeMin = lo - 0.02 * largest;
        set.volumeMax = hi + 0.02 * largest;
        const glm::dvec3 centre = 0.5 * (set.volumeMin + set.volumeMax);
        const double radius = 0.5 * glm::length(set.volumeMax - set.volumeMin);
        const double distance = double(options.distanceInRadii) * radius;

        RenderOptions render;
        render.width = render.height = options.resolution;
        render.samplesPerPixel = options.samplesPerPixel;
        render.lighting = options.lighting;
        render.transparentBackground = true;

        const ReferenceRenderer renderer(model);
        const int n = options.cameraCount;
        const char* nameFormat = n <= 100 ? "cam%02d" : "cam%03d";
        report(progress, "capture: views", 0.0f);
        for (int k = 0; k < n; ++k)
        {
            const glm::dvec2 placement = cameraPlacement(k, n);
            const glm::dvec3 direction = orbitDirection(placement.x, placement.y);
            CameraSpec spec;
            spec.position = glm::vec3(centre + distance * direction);
            spec.target = glm::vec3(centre);
            // Straight above or below, +y is the view axis: then image up is towards -z.
            const bool vertical = glm::length(glm::cross(direction, glm::dvec3(0.0, 1.0, 0.0))) < 1e-6;
            spec.up = vertical ? glm::vec3(0.0f, 0.0f, -1.0f) : glm::vec3(0.0f, 1.0f, 0.0f);
            spec.fovYDegrees = options.fovYDegrees;
            spec.nearClip = float(std::max(0.5 * (distance - radius), 1e-4 * radius));
            spec.farClip = float(distance + 2.0 * radius);

            char name[16];
            std::snprintf(name, sizeof(name), nameFormat, k);
            set.cameras.push_back(captureCameraFromSpec(spec, options.resolution, options.resolution, name));
            set.images.push_back(renderer.render(spec, render).colour);
            report(progress, "capture: views", float(k + 1) / float(n));
        }
        Result<void> complete = set.validate(label);
        if (!complete)
            return complete.error();
        return set;
    }
}

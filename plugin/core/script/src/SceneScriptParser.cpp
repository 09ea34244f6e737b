// SceneScript: parsing (nlohmann::json for values, a position scan for line/column of
// every key) and the script's sun as the renderers' lighting. Instance files are read in
// InstanceFile.cpp, placements sampled in Placement.cpp, the camera path in CameraPath.cpp.
#include "TreeLod/SceneScript.h"

#include "InstanceFile.h"
#include "Placement.h"
#include "SceneScriptDetail.h"
#include "TreeLod/AtomicFile.h"
#include "TreeLod/TreePreset.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <optional>

namespace TreeLod
{
    namespace
    {
        using Json = nlohmann::json;
        using namespace SceneScriptDetail;

        /// Internal only: thrown by the readers below, turned into a Result at the top.
        struct ScriptError
        {
            std::string pointer; ///< JSON pointer of the offending key ("" = root)
            std::string reason;
        };

        [[noreturn]] void bad(const std::string& pointer, const std::string& reason)
        {
            throw ScriptError{pointer, reason};
        }

        std::string child(const std::string& pointer, const std::string& key)
        {
            std::string escaped;
            for (char c : key)
            {
                if (c == '~')
                    escaped += "~0";
                else if (c == '/')
                    escaped += "~1";
                else
                    escaped += c;
            }
            return pointer + "/" + escaped;
        }

        std::string child(const std::string& pointer, std::size_t index)
        {
            return pointer + "/" + std::to_string(index);
        }

        // ---- positions: byte offset of every key (object members) and value (array elements) ----

        /// Walks text that nlohmann already accepted (so it is valid JSON with comments) and
        /// records where each JSON pointer starts: the key's opening quote for object members,
        /// the value for array elements and the root. Reports duplicate keys, which nlohmann
        /// would silently collapse. After a number overflow nlohmann stops early, so the text may
        /// be anything: every read stays in bounds, a bad string throws Json::exception.
        class PositionScan
        {
        public:
            explicit PositionScan(const std::string& text) : mText(text) {}

            void run()
            {
                if (mText.compare(0, 3, "\xEF\xBB\xBF") == 0)
                    mAt = 3; // nlohmann skips a UTF-8 byte order mark
                value("");
            }

            std::map<std::string, std::size_t> offsets;
            /// If set before run(), tokenAt gets the pointer of the first scalar spelt exactly `token`.
            std::string token;
            std::optional<std::string> tokenAt;

        private:
            const std::string& mText;
            std::size_t mAt = 0;

            char peek() const { return mAt < mText.size() ? mText[mAt] : '\0'; }

            void skipSpace()
            {
                while (mAt < mText.size())
                {
                    char c = mText[mAt];
                    if (c == ' ' || c == '\t' || c == '\n' || c == '\r')
                        ++mAt;
                    else if (c == '/' && mAt + 1 < mText.size() && mText[mAt + 1] == '/')
                    {
                        // As nlohmann ends it: at a line feed, a carriage return or a NUL, which
                        // belongs to the comment.
                        mAt += 2;
                        while (mAt < mText.size() && mText[mAt] != '\n' && mText[mAt] != '\r' && mText[mAt] != '\0')
                            ++mAt;
                        if (mAt < mText.size())
                            ++mAt;
                    }
                    else if (c == '/' && mAt + 1 < mText.size() && mText[mAt + 1] == '*')
                    {
                        std::size_t end = mText.find("*/", mAt + 2);
                        mAt = end == std::string::npos ? mText.size() : end + 2;
                    }
                    else
                        break;
                }
            }

            std::string string()
            {
                std::size_t start = mAt++;
                while (mAt < mText.size() && mText[mAt] != '"')
                    mAt += mText[mAt] == '\\' ? 2 : 1;
                ++mAt;
                return Json::parse(mText.substr(start, mAt - start)).get<std::string>();
            }

            void value(const std::string& pointer)
            {
                skipSpace();
                mAt = std::min(mAt, mText.size()); // past a ':' or ',' the text did not have
                offsets.emplace(pointer, mAt); // members already hold their key's offset
                char c = peek();
                if (c == '{' || c == '[')
                {
                    const bool object = c == '{';
                    ++mAt;
                    skipSpace();
                    if (peek() == (object ? '}' : ']'))
                    {
                        ++mAt;
                        return;
                    }
                    for (std::size_t index = 0;; ++index)
                    {
                        skipSpace();
                        if (object)
                        {
                            std::size_t keyAt = mAt;
                            std::string member = child(pointer, string());
                            if (!offsets.emplace(member, keyAt).second)
                            {
                                offsets[member] = keyAt;
                                bad(member, "duplicate key");
                            }
                            skipSpace();
                            ++mAt; // ':'
                            value(member);
                        }
                        else
                            value(child(pointer, index));
                        skipSpace();
                        const char next = peek();
                        ++mAt;
                        if (next != ',')
                            return; // '}' or ']' (or the end of a text nlohmann stopped short of)
                    }
                }
                if (c == '"')
                {
                    string();
                    return;
                }
                const std::size_t start = mAt;
                while (mAt < mText.size() && std::string(",]} \t\r\n/").find(mText[mAt]) == std::string::npos)
                    ++mAt;
                if (!tokenAt && !token.empty() && mText.compare(start, mAt - start, token) == 0)
                    tokenAt = pointer;
            }
        };

        std::string lineColumn(const std::string& text, std::size_t offset)
        {
            offset = std::min(offset, text.size());
            std::size_t line = 1, lineStart = 0;
            for (std::size_t i = 0; i < offset; ++i)
                if (text[i] == '\n')
                {
                    ++line;
                    lineStart = i + 1;
                }
            return "line " + std::to_string(line) + ", column " + std::to_string(offset - lineStart + 1);
        }

        // ---- typed readers -----------------------------------------------------------------

        const char* typeName(const Json& j)
        {
            return j.type_name(); // "object", "array", "string", "number", "boolean", "null"
        }

        void expectObject(const Json& j, const std::string& pointer)
        {
            if (!j.is_object())
                bad(pointer, std::string("expected an object, got ") + typeName(j));
        }

        void expectArray(const Json& j, const std::string& pointer, std::size_t minSize = 0)
        {
            if (!j.is_array())
                bad(pointer, std::string("expected an array, got ") + typeName(j));
            if (j.size() < minSize)
                bad(pointer, "expected at least " + std::to_string(minSize) + " entries, got " +
                                 std::to_string(j.size()));
        }

        /// Unknown keys are errors: a typo must not pass silently.
        void allowKeys(const Json& j, const std::string& pointer, std::initializer_list<const char*> keys)
        {
            expectObject(j, pointer);
            for (auto it = j.begin(); it != j.end(); ++it)
            {
                bool known = false;
                for (const char* k : keys)
                    known = known || it.key() == k;
                if (!known)
                {
                    std::string list;
                    for (const char* k : keys)
                        list += (list.empty() ? "" : ", ") + std::string(k);
                    bad(child(pointer, it.key()), "unknown key '" + it.key() + "' (expected one of: " + list + ")");
                }
            }
        }

        const Json* find(const Json& j, const char* key)
        {
            auto it = j.find(key);
            return it == j.end() ? nullptr : &*it;
        }

        const Json& need(const Json& j, const std::string& pointer, const char* key)
        {
            const Json* v = find(j, key);
            if (!v)
                bad(child(pointer, key), "missing required key");
            return *v;
        }

        /// A finite number in [lo, hi] (or (lo, hi] when loOpen).
        double number(const Json& j, const std::string& pointer, double lo, double hi, bool loOpen = false)
        {
            if (!j.is_number())
                bad(pointer, std::string("expected a number, got ") + typeName(j));
            double v = j.get<double>();
            if (!std::isfinite(v))
                bad(pointer, "not a finite number");
            if (loOpen ? !(v > lo) : !(v >= lo))
                bad(pointer, "must be " + std::string(loOpen ? "> " : ">= ") + formatNumber(lo) + ", got " +
                                 formatNumber(v));
            if (v > hi)
                bad(pointer, "must be <= " + formatNumber(hi) + ", got " + formatNumber(v));
            return v;
        }

        std::int64_t integer(const Json& j, const std::string& pointer, std::int64_t lo, std::int64_t hi)
        {
            if (!j.is_number_integer())
                bad(pointer, std::string("expected an integer, got ") + (j.is_number() ? "a fraction" : typeName(j)));
            if (j.is_number_unsigned() && j.get<std::uint64_t>() > std::uint64_t(hi))
                bad(pointer, "must be <= " + std::to_string(hi));
            std::int64_t v = j.get<std::int64_t>();
            if (v < lo)
                bad(pointer, "must be >= " + std::to_string(lo) + ", got " + std::to_string(v));
            if (v > hi)
                bad(pointer, "must be <= " + std::to_string(hi) + ", got " + std::to_string(v));
            return v;
        }

        std::string text(const Json& j, const std::string& pointer, bool allowEmpty = false)
        {
            if (!j.is_string())
                bad(pointer, std::string("expected a string, got ") + typeName(j));
            if (!allowEmpty && j.get<std::string>().empty())
                bad(pointer, "must not be empty");
            return j.get<std::string>();
        }

        bool flag(const Json& j, const std::string& pointer)
        {
            if (!j.is_boolean())
                bad(pointer, std::string("expected true or false, got ") + typeName(j));
            return j.get<bool>();
        }

        /// An array of exactly n finite numbers, each in [lo, hi].
        std::vector<double> numbers(const Json& j, const std::string& pointer, std::size_t n,
                                    double lo = -1e9, double hi = 1e9)
        {
            if (!j.is_array() || j.size() != n)
                bad(pointer, "expected an array of " + std::to_string(n) + " numbers");
            std::vector<double> out;
            for (std::size_t i = 0; i < n; ++i)
                out.push_back(number(j[i], child(pointer, i), lo, hi));
            return out;
        }

        glm::vec3 vec3(const Json& j, const std::string& pointer, double lo = -1e9, double hi = 1e9)
        {
            std::vector<double> v = numbers(j, pointer, 3, lo, hi);
            return glm::vec3(float(v[0]), float(v[1]), float(v[2]));
        }

        /// Technique names as in the Ogre plugin's registry: lower-case letters, digits, '-'.
        bool validTechniqueName(const std::string& name)
        {
            if (name.empty() || name.size() > 32 || !(name[0] >= 'a' && name[0] <= 'z'))
                return false;
            for (char c : name)
                if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-'))
                    return false;
            return true;
        }

        // ---- sections ------------------------------------------------------------------------

        std::string resolvePath(const std::string& baseDir, const std::string& path)
        {
            std::filesystem::path p(path);
            if (p.is_relative() && !baseDir.empty())
                p = std::filesystem::path(baseDir) / p;
            return p.lexically_normal().string();
        }

        SceneGround readGround(const Json& j, const std::string& pointer, const std::string& baseDir,
                               const GreyImageReader& readImage)
        {
            allowKeys(j, pointer, {"kind", "size", "image", "heightScale"});
            SceneGround g;
            std::string kind = text(need(j, pointer, "kind"), child(pointer, "kind"));
            g.size = float(number(need(j, pointer, "size"), child(pointer, "size"), 0.0, 1e6, true));
            if (kind == "plane")
            {
                for (const char* key : {"image", "heightScale"})
                    if (find(j, key))
                        bad(child(pointer, key), "only for \"kind\": \"heightfield\"");
                return g;
            }
            if (kind != "heightfield")
                bad(child(pointer, "kind"), "unknown ground kind '" + kind + "' (expected plane or heightfield)");
            g.kind = SceneGround::Kind::Heightfield;
            g.heightScale = float(number(need(j, pointer, "heightScale"), child(pointer, "heightScale"), 0.0, 1e4));
            std::string imagePointer = child(pointer, "image");
            g.image = resolvePath(baseDir, text(need(j, pointer, "image"), imagePointer));
            if (!readImage)
                bad(imagePointer, "no image reader given (the program reading this script passes readGreyImage "
                                  "or readGreyImageOgre to loadSceneScript)");
            Result<GreyImage> image = readImage(g.image);
            if (!image)
                bad(imagePointer, image.error().message());
            if (image->width < 2 || image->height < 2)
                bad(imagePointer, "heightfield image must be at least 2 x 2 pixels");
            if (image->values.size() != std::size_t(image->width) * std::size_t(image->height))
                bad(imagePointer, "the image reader returned " + std::to_string(image->values.size()) +
                                      " values for " + std::to_string(image->width) + " x " +
                                      std::to_string(image->height) + " pixels");
            for (float v : image->values)
                if (!(v >= 0.0f && v <= 1.0f))
                    bad(imagePointer, "the image reader returned a grey value outside [0, 1]: " + formatNumber(v));
            g.heightsWidth = image->width;
            g.heightsHeight = image->height;
            g.heights = std::move(image->values);
            return g;
        }

        SceneSpecies readSpecies(const Json& j, const std::string& pointer, const std::string& baseDir)
        {
            allowKeys(j, pointer, {"name", "source", "seed", "leaves", "height", "techniques", "scale"});
            SceneSpecies s;
            s.name = text(need(j, pointer, "name"), child(pointer, "name"));
            std::string sourcePointer = child(pointer, "source");
            std::string source = text(need(j, pointer, "source"), sourcePointer);
            if (source.rfind("preset:", 0) == 0)
            {
                s.preset = source.substr(7);
                TreePreset preset;
                if (!parsePreset(s.preset, preset))
                    bad(sourcePointer, "unknown preset '" + s.preset + "' (expected " + presetNames() + ")");
                if (const Json* v = find(j, "seed"))
                    s.seed = std::uint32_t(integer(*v, child(pointer, "seed"), 0, 0xffffffffll));
                if (const Json* v = find(j, "leaves"))
                    s.leaves = std::uint32_t(integer(*v, child(pointer, "leaves"), 100, 200000));
                if (const Json* v = find(j, "height"))
                    s.height = float(number(*v, child(pointer, "height"), 0.1, 1000.0));
            }
            else
            {
                for (const char* key : {"seed", "leaves", "height"})
                    if (find(j, key))
                        bad(child(pointer, key), "only for \"preset:NAME\" sources");
                s.source = resolvePath(baseDir, source);
                std::error_code ec;
                if (!std::filesystem::is_regular_file(s.source, ec))
                    bad(sourcePointer, "no such file: " + s.source);
            }

            std::string techPointer = child(pointer, "techniques");
            const Json& tech = need(j, pointer, "techniques");
            if (tech.is_string())
            {
                if (tech.get<std::string>() != "auto")
                    bad(techPointer, "expected \"auto\" or an array of bands");
            }
            else
            {
                expectArray(tech, techPointer, 1);
                s.autoTechnique = false;
                bool byPixels = false;
                for (std::size_t i = 0; i < tech.size(); ++i)
                {
                    std::string bandPointer = child(techPointer, i);
                    allowKeys(tech[i], bandPointer, {"technique", "maxDistance", "minPixels"});
                    TechniqueBand band;
                    band.technique = text(need(tech[i], bandPointer, "technique"), child(bandPointer, "technique"));
                    if (!validTechniqueName(band.technique) || band.technique == "auto")
                        bad(child(bandPointer, "technique"),
                            "'" + band.technique + "' is not a technique name (lower-case letters, digits, '-')");
                    const Json* dist = find(tech[i], "maxDistance");
                    const Json* pixels = find(tech[i], "minPixels");
                    const bool last = i + 1 == tech.size();
                    if (dist && pixels)
                        bad(child(bandPointer, "minPixels"), "a band has maxDistance or minPixels, not both");
                    if (!dist && !pixels && !last)
                        bad(child(bandPointer, "maxDistance"),
                            "missing required key (maxDistance or minPixels; only the last band is open-ended)");
                    if (dist || pixels)
                    {
                        if (i == 0)
                            byPixels = pixels != nullptr;
                        else if (byPixels != (pixels != nullptr))
                            bad(child(bandPointer, pixels ? "minPixels" : "maxDistance"),
                                "all bands of a species use the same measure, maxDistance or minPixels");
                    }
                    if (dist)
                    {
                        band.maxDistance = float(number(*dist, child(bandPointer, "maxDistance"), 0.0, 1e7, true));
                        if (i > 0 && !(band.maxDistance > s.bands.back().maxDistance))
                            bad(child(bandPointer, "maxDistance"), "must be greater than the previous band's");
                    }
                    if (pixels)
                    {
                        band.minPixels = float(number(*pixels, child(bandPointer, "minPixels"), 0.0, 1e5, true));
                        if (i > 0 && !(band.minPixels < s.bands.back().minPixels))
                            bad(child(bandPointer, "minPixels"), "must be less than the previous band's");
                    }
                    s.bands.push_back(band);
                }
            }

            if (const Json* v = find(j, "scale"))
            {
                std::string scalePointer = child(pointer, "scale");
                if (v->is_number())
                    s.scaleMin = s.scaleMax = float(number(*v, scalePointer, 0.0, 1e3, true));
                else
                {
                    if (!v->is_array() || v->size() != 2)
                        bad(scalePointer, "expected a number or [min, max]");
                    s.scaleMin = float(number((*v)[0], child(scalePointer, 0), 0.0, 1e3, true));
                    s.scaleMax = float(number((*v)[1], child(scalePointer, 1), s.scaleMin, 1e3));
                }
            }
            return s;
        }

        SceneArea readArea(const Json& j, const std::string& pointer, float groundSize)
        {
            allowKeys(j, pointer, {"rect", "disc", "innerRadius"});
            const Json* rect = find(j, "rect");
            const Json* disc = find(j, "disc");
            if (!rect && !disc)
                bad(child(pointer, "rect"), "missing required key (rect or disc)");
            if (rect && disc)
                bad(child(pointer, "disc"), "an area is a rect or a disc, not both");
            SceneArea a;
            const double half = 0.5 * groundSize;
            if (rect)
            {
                if (find(j, "innerRadius"))
                    bad(child(pointer, "innerRadius"), "only for discs");
                std::string rp = child(pointer, "rect");
                std::vector<double> v = numbers(*rect, rp, 4, -half, half);
                if (!(v[2] > v[0]) || !(v[3] > v[1]))
                    bad(rp, "expected [minX, minZ, maxX, maxZ] with max > min");
                a.min = glm::vec2(float(v[0]), float(v[1]));
                a.max = glm::vec2(float(v[2]), float(v[3]));
                return a;
            }
            std::string dp = child(pointer, "disc");
            std::vector<double> v = numbers(*disc, dp, 3);
            if (!(v[2] > 0.0))
                bad(child(dp, 2), "radius must be > 0");
            if (std::abs(v[0]) + v[2] > half || std::abs(v[1]) + v[2] > half)
                bad(dp, "disc reaches beyond the ground (size " + formatNumber(groundSize) + " m)");
            a.kind = SceneArea::Kind::Disc;
            a.centre = glm::vec2(float(v[0]), float(v[1]));
            a.radius = float(v[2]);
            if (const Json* inner = find(j, "innerRadius"))
            {
                a.innerRadius = float(number(*inner, child(pointer, "innerRadius"), 0.0, v[2]));
                if (!(a.innerRadius < a.radius))
                    bad(child(pointer, "innerRadius"), "must be less than the radius");
            }
            return a;
        }

        ScenePlacement readPlacement(const Json& j, const std::string& pointer, const SceneScript& script,
                                     const std::string& baseDir)
        {
            allowKeys(j, pointer, {"species", "positions", "random", "file"});
            ScenePlacement p;
            std::string speciesPointer = child(pointer, "species");
            const Json& species = need(j, pointer, "species");
            std::vector<std::pair<std::string, std::string>> names; // (name, pointer)
            if (species.is_array())
            {
                expectArray(species, speciesPointer, 1);
                for (std::size_t i = 0; i < species.size(); ++i)
                    names.emplace_back(text(species[i], child(speciesPointer, i)), child(speciesPointer, i));
            }
            else
                names.emplace_back(text(species, speciesPointer), speciesPointer);
            for (const auto& [name, namePointer] : names)
            {
                const std::string& wanted = name; // C++17 lambdas cannot capture structured bindings
                auto it = std::find_if(script.species.begin(), script.species.end(),
                                       [&wanted](const SceneSpecies& s) { return s.name == wanted; });
                if (it == script.species.end())
                    bad(namePointer, "no species named '" + name + "'");
                p.species.push_back(std::uint32_t(it - script.species.begin()));
            }

            const Json* positions = find(j, "positions");
            const Json* random = find(j, "random");
            const Json* file = find(j, "file");
            if (!positions && !random && !file)
                bad(child(pointer, "positions"), "missing required key (positions, random or file)");
            if (int(positions != nullptr) + int(random != nullptr) + int(file != nullptr) > 1)
                bad(child(pointer, file ? "file" : "random"), "a placement has one of positions, random or file");
            const double half = 0.5 * script.ground.size;
            if (file)
            {
                const std::string fp = child(pointer, "file");
                p.file = resolvePath(baseDir, text(*file, fp));
                std::error_code ec;
                if (!std::filesystem::is_regular_file(p.file, ec))
                    bad(fp, "no such file: " + p.file);
                readInstanceFile(p.file, p, script);
                return p;
            }
            if (positions)
            {
                std::string pp = child(pointer, "positions");
                if (p.species.size() != 1)
                    bad(speciesPointer, "explicit positions take one species");
                expectArray(*positions, pp, 1);
                for (std::size_t i = 0; i < positions->size(); ++i)
                {
                    const Json& e = (*positions)[i];
                    std::string ep = child(pp, i);
                    if (!e.is_array() || e.size() < 2 || e.size() > 4)
                        bad(ep, "expected [x, z], [x, z, rotationDegrees] or [x, z, rotationDegrees, scale]");
                    glm::vec4 v(float(number(e[0], child(ep, 0), -half, half)),
                                float(number(e[1], child(ep, 1), -half, half)), 0.0f, 1.0f);
                    if (e.size() > 2)
                        v.z = float(number(e[2], child(ep, 2), -360.0, 360.0) * PI / 180.0);
                    if (e.size() > 3)
                        v.w = float(number(e[3], child(ep, 3), 0.0, 1e3, true));
                    p.positions.push_back(v);
                }
                return p;
            }

            std::string rp = child(pointer, "random");
            allowKeys(*random, rp, {"seed", "count", "density", "area", "exclude", "clumping"});
            p.random = true;
            p.seed = std::uint32_t(integer(need(*random, rp, "seed"), child(rp, "seed"), 0, 0xffffffffll));
            p.area = readArea(need(*random, rp, "area"), child(rp, "area"), script.ground.size);
            if (const Json* ex = find(*random, "exclude"))
            {
                expectArray(*ex, child(rp, "exclude"));
                std::size_t before = 0;
                for (const ScenePlacement& earlier : script.placements)
                    before += earlier.exclude.size();
                if (before + ex->size() > MAX_EXCLUSIONS)
                    bad(child(rp, "exclude"), "the placements exclude " + std::to_string(before + ex->size()) +
                                                  " areas in all (" + std::to_string(ex->size()) +
                                                  " here), more than " + std::to_string(MAX_EXCLUSIONS));
                for (std::size_t i = 0; i < ex->size(); ++i)
                    p.exclude.push_back(readArea((*ex)[i], child(child(rp, "exclude"), i), script.ground.size));
            }
            p.freeAreaM2 = freeArea(p.area, p.exclude);
            const double free = p.freeAreaM2;
            if (free <= 0.0)
                bad(child(rp, "exclude"), "leaves no free ground in the area");
            const Json* count = find(*random, "count");
            const Json* density = find(*random, "density");
            if (!count && !density)
                bad(child(rp, "count"), "missing required key (count or density)");
            if (count && density)
                bad(child(rp, "density"), "give count or density, not both");
            if (count)
                p.count = std::uint32_t(integer(*count, child(rp, "count"), 1, MAX_TREES));
            else
            {
                std::string dp = child(rp, "density");
                p.density = float(number(*density, dp, 0.0, 1e6, true));
                double n = std::round(double(p.density) * free / 10000.0);
                if (n < 1.0)
                    bad(dp, "gives no tree on " + formatNumber(free) + " m² (density is per hectare)");
                if (n > MAX_TREES)
                    bad(dp, "gives more than " + std::to_string(MAX_TREES) + " trees");
                p.count = std::uint32_t(n);
            }
            if (const Json* c = find(*random, "clumping"))
                p.clumping = float(number(*c, child(rp, "clumping"), 0.0, 1.0));
            return p;
        }

        SceneSun readSun(const Json& j, const std::string& pointer)
        {
            allowKeys(j, pointer, {"direction", "azimuth", "elevation", "colour", "ambient"});
            SceneSun sun;
            const Json* dir = find(j, "direction");
            const Json* az = find(j, "azimuth");
            const Json* el = find(j, "elevation");
            if (dir && (az || el))
                bad(child(pointer, az ? "azimuth" : "elevation"), "give direction or azimuth/elevation, not both");
            if (dir)
            {
                // Normalised in doubles, then y > 0 in floats: [0, 1e-38, 0] has no length in
                // floats (normalising there gives NaN), and [1e9, 1e-38, 0] is above the horizon
                // only in doubles.
                const std::vector<double> d = numbers(*dir, child(pointer, "direction"), 3, -1e9, 1e9);
                const glm::dvec3 v(d[0], d[1], d[2]);
                const double length = glm::length(v);
                if (!(length > 0.0))
                    bad(child(pointer, "direction"), "a zero vector has no direction");
                sun.direction = glm::vec3(v / length);
                if (!(sun.direction.y > 0.0f))
                    bad(child(pointer, "direction"), "the sun must be above the horizon (y > 0, towards the sun)");
            }
            else
            {
                if (!az)
                    bad(child(pointer, "azimuth"), "missing required key (direction or azimuth and elevation)");
                if (!el)
                    bad(child(pointer, "elevation"), "missing required key (direction or azimuth and elevation)");
                double a = number(*az, child(pointer, "azimuth"), -360.0, 360.0) * PI / 180.0;
                double e = number(*el, child(pointer, "elevation"), 0.0, 90.0, true) * PI / 180.0;
                // Azimuth as in CameraSpec::framing: 0 = from +Z, 90 = from +X.
                sun.direction = glm::vec3(float(std::sin(a) * std::cos(e)), float(std::sin(e)),
                                          float(std::cos(a) * std::cos(e)));
                if (!(sun.direction.y > 0.0f))
                    bad(child(pointer, "elevation"), "so low that the sun's direction rounds to the horizon (y = 0)");
            }
            if (const Json* c = find(j, "colour"))
                sun.colour = vec3(*c, child(pointer, "colour"), 0.0, 100.0);
            if (const Json* c = find(j, "ambient"))
                sun.ambient = vec3(*c, child(pointer, "ambient"), 0.0, 100.0);
            return sun;
        }

        SceneShadows readShadows(const Json& j, const std::string& pointer)
        {
            allowKeys(j, pointer, {"enabled", "textureSize", "camera", "lodBias"});
            SceneShadows s;
            s.enabled = flag(need(j, pointer, "enabled"), child(pointer, "enabled"));
            if (const Json* v = find(j, "textureSize"))
            {
                s.textureSize = int(integer(*v, child(pointer, "textureSize"), 256, 16384));
                if ((s.textureSize & (s.textureSize - 1)) != 0)
                    bad(child(pointer, "textureSize"), "must be a power of two");
            }
            if (const Json* v = find(j, "camera"))
            {
                s.camera = text(*v, child(pointer, "camera"));
                if (s.camera != "focused" && s.camera != "lispsm" && s.camera != "pssm")
                    bad(child(pointer, "camera"),
                        "unknown shadow camera '" + s.camera + "' (expected focused, lispsm, pssm)");
            }
            if (const Json* v = find(j, "lodBias"))
                s.lodBias = float(number(*v, child(pointer, "lodBias"), 0.0, 1e6, true));
            return s;
        }

        WindParameters readWind(const Json& j, const std::string& pointer)
        {
            allowKeys(j, pointer, {"strength", "direction", "gustiness", "gustWavelength"});
            WindParameters w;
            w.strength = float(number(need(j, pointer, "strength"), child(pointer, "strength"), 0.0, 100.0));
            if (const Json* v = find(j, "direction"))
            {
                const std::vector<double> d = numbers(*v, child(pointer, "direction"), 2, -1e9, 1e9);
                const glm::dvec2 dir(d[0], d[1]);
                if (!(glm::length(dir) > 0.0))
                    bad(child(pointer, "direction"), "a zero vector has no direction");
                w.direction = glm::vec2(dir / glm::length(dir));
            }
            if (const Json* v = find(j, "gustiness"))
                w.gustiness = float(number(*v, child(pointer, "gustiness"), 0.0, 1.0));
            if (const Json* v = find(j, "gustWavelength"))
                w.gustWavelength = float(number(*v, child(pointer, "gustWavelength"), 0.0, 1e6, true));
            return w;
        }

        SceneCamera readCamera(const Json& j, const std::string& pointer)
        {
            allowKeys(j, pointer, {"fovY", "near", "far", "interpolation", "keyframes"});
            SceneCamera c;
            if (const Json* v = find(j, "fovY"))
                c.fovYDegrees = float(number(*v, child(pointer, "fovY"), 1.0, 170.0));
            if (const Json* v = find(j, "near"))
                c.nearClip = float(number(*v, child(pointer, "near"), 0.0, 1e4, true));
            if (const Json* v = find(j, "far"))
                c.farClip = float(number(*v, child(pointer, "far"), c.nearClip, 1e7, true));
            if (!(c.farClip > c.nearClip))
                bad(child(pointer, find(j, "far") ? "far" : "near"), "far must be greater than near");
            if (const Json* v = find(j, "interpolation"))
            {
                std::string mode = text(*v, child(pointer, "interpolation"));
                if (mode != "catmull-rom" && mode != "linear")
                    bad(child(pointer, "interpolation"),
                        "unknown interpolation '" + mode + "' (expected catmull-rom, linear)");
                c.linear = mode == "linear";
            }
            std::string kp = child(pointer, "keyframes");
            const Json& keys = need(j, pointer, "keyframes");
            expectArray(keys, kp, 1);
            for (std::size_t i = 0; i < keys.size(); ++i)
            {
                std::string ep = child(kp, i);
                allowKeys(keys[i], ep, {"time", "position", "target"});
                SceneKeyframe k;
                k.time = number(need(keys[i], ep, "time"), child(ep, "time"), -1e7, 1e7);
                if (i > 0 && !(k.time > c.keyframes.back().time))
                    bad(child(ep, "time"), "must be greater than the previous keyframe's time (" +
                                               formatNumber(c.keyframes.back().time) + ")");
                k.position = vec3(need(keys[i], ep, "position"), child(ep, "position"));
                k.target = vec3(need(keys[i], ep, "target"), child(ep, "target"));
                glm::vec3 view = k.target - k.position;
                float length = glm::length(view);
                if (!(length > 1e-4f))
                    bad(child(ep, "target"), "the camera looks at its own position");
                if (std::abs(view.y) > 0.9999f * length)
                    bad(child(ep, "target"), "the camera looks straight up or down (its up is +Y)");
                c.keyframes.push_back(k);
            }
            return c;
        }

        SceneScript readScript(const Json& root, const std::string& baseDir, const GreyImageReader& readImage)
        {
            allowKeys(root, "", {"name", "description", "ground", "species", "placements", "sun", "shadows", "lod",
                                 "wind", "camera", "resolution", "frames", "counts"});
            SceneScript s;
            s.name = text(need(root, "", "name"), "/name");
            if (const Json* v = find(root, "description"))
                s.description = text(*v, "/description", true);
            s.ground = readGround(need(root, "", "ground"), "/ground", baseDir, readImage);

            const Json& species = need(root, "", "species");
            expectArray(species, "/species", 1);
            for (std::size_t i = 0; i < species.size(); ++i)
            {
                s.species.push_back(readSpecies(species[i], child("/species", i), baseDir));
                for (std::size_t k = 0; k < i; ++k)
                    if (s.species[k].name == s.species[i].name)
                        bad(child(child("/species", i), "name"), "species '" + s.species[i].name + "' defined twice");
            }

            const Json& placements = need(root, "", "placements");
            expectArray(placements, "/placements", 1);
            std::uint64_t explicitTrees = 0, totalTrees = 0;
            bool anyRandom = false;
            for (std::size_t i = 0; i < placements.size(); ++i)
            {
                const std::string pointer = child("/placements", i);
                s.placements.push_back(readPlacement(placements[i], pointer, s, baseDir));
                const ScenePlacement& p = s.placements.back();
                explicitTrees += p.positions.size();
                anyRandom = anyRandom || p.random;
                // generatePlacements() makes every tree at once: the whole scene has a bound, not
                // only each placement.
                const std::uint64_t trees = p.random ? p.count : p.positions.size();
                totalTrees += trees;
                if (totalTrees > MAX_TREES)
                {
                    const char* key = !p.random             ? (p.file.empty() ? "positions" : "file")
                                      : p.density > 0.0f ? "density"
                                                         : "count";
                    bad(p.random ? child(child(pointer, "random"), key) : child(pointer, key),
                        "the placements add up to " + std::to_string(totalTrees) + " trees (" +
                            std::to_string(trees) + " here), more than " + std::to_string(MAX_TREES));
                }
            }

            if (const Json* v = find(root, "sun"))
                s.sun = readSun(*v, "/sun");
            if (const Json* v = find(root, "shadows"))
                s.shadows = readShadows(*v, "/shadows");
            if (const Json* v = find(root, "wind"))
                s.wind = readWind(*v, "/wind");
            if (const Json* v = find(root, "lod"))
            {
                allowKeys(*v, "/lod", {"maxError", "shadowMaxError", "frameBudgetMs", "memoryBudgetMB", "transition", "occlusion"});
                if (const Json* e = find(*v, "maxError"))
                    s.lod.maxError = float(number(*e, "/lod/maxError", 0.0, 1.0));
                if (const Json* e = find(*v, "shadowMaxError"))
                    s.lod.shadowMaxError = float(number(*e, "/lod/shadowMaxError", 0.0, 1.0));
                if (const Json* e = find(*v, "frameBudgetMs"))
                    s.lod.frameBudgetMs = float(number(*e, "/lod/frameBudgetMs", 0.0, 1e6));
                if (const Json* e = find(*v, "memoryBudgetMB"))
                    s.lod.memoryBudgetMB = float(number(*e, "/lod/memoryBudgetMB", 0.0, 1e9));
                if (const Json* e = find(*v, "transition"))
                    s.lod.transition = float(number(*e, "/lod/transition", 0.0, ForestInstances::MAX_TRANSITION));
                if (const Json* e = find(*v, "occlusion"))
                    s.lod.occlusion = flag(*e, "/lod/occlusion");
            }
            s.camera = readCamera(need(root, "", "camera"), "/camera");

            const Json& resolution = need(root, "", "resolution");
            if (!resolution.is_array() || resolution.size() != 2)
                bad("/resolution", "expected [width, height]");
            s.width = int(integer(resolution[0], "/resolution/0", 16, 16384));
            s.height = int(integer(resolution[1], "/resolution/1", 16, 16384));
            s.frames = std::uint32_t(integer(need(root, "", "frames"), "/frames", 1, 10000000));

            if (const Json* v = find(root, "counts"))
            {
                expectArray(*v, "/counts", 1);
                for (std::size_t i = 0; i < v->size(); ++i)
                {
                    std::uint32_t n = std::uint32_t(integer((*v)[i], child("/counts", i), 1, MAX_TREES));
                    if (n > explicitTrees && !anyRandom)
                        bad(child("/counts", i), "more trees than the explicit positions and no random placement");
                    s.counts.push_back(n);
                }
            }
            return s;
        }
    }

    Result<SceneScript> parseSceneScript(const std::string& text, const std::string& label, const std::string& baseDir,
                                         const GreyImageReader& readImage)
    {
        Json root;
        std::string overflow; // the number nlohmann found too large, as written
        try
        {
            root = Json::parse(text, nullptr, true, true);
        }
        catch (const Json::parse_error& e)
        {
            // e.byte: 1-based index of the last character read (where the error shows).
            std::string what = e.what();
            std::size_t column = what.find("column ");
            std::size_t reasonAt = column == std::string::npos ? what.find("] ") : what.find(": ", column);
            std::string reason = reasonAt == std::string::npos ? what : what.substr(reasonAt + 2);
            return fail(label, lineColumn(text, e.byte > 0 ? e.byte - 1 : 0), reason);
        }
        catch (const Json::out_of_range& e)
        {
            // A number beyond a double ("number overflow parsing '1e999'"), refused without its
            // position: the scan below finds the first number written so.
            std::string what = e.what();
            std::size_t open = what.find("parsing '"), close = what.rfind('\'');
            if (open == std::string::npos || close <= open + 9)
                return fail(label, "", what);
            overflow = what.substr(open + 9, close - open - 9);
        }
        PositionScan scan(text);
        scan.token = overflow;
        try
        {
            scan.run();
            if (!overflow.empty())
                bad(scan.tokenAt.value_or(""), overflow + " is not a finite number (beyond the range of a double)");
            SceneScript script = readScript(root, baseDir, readImage);
            script.file = label;
            return script;
        }
        catch (const InstanceFileError& e)
        {
            return e.error;
        }
        catch (const ScriptError& e)
        {
            // Report at the key itself, or at the nearest enclosing one that exists (a missing key).
            std::string at = e.pointer;
            while (!at.empty() && !scan.offsets.count(at))
                at.resize(at.rfind('/'));
            std::size_t offset = scan.offsets.count(at) ? scan.offsets[at] : 0;
            return fail(label, lineColumn(text, offset) + ", key " + (e.pointer.empty() ? "/" : e.pointer), e.reason);
        }
        catch (const Json::exception&)
        {
            // Only after an overflow (a text nlohmann parsed scans whole): a syntax error further
            // on, which nlohmann did not reach. The number comes first in the text: report it.
            const std::size_t at = text.find(overflow);
            return fail(label, lineColumn(text, at == std::string::npos ? 0 : at),
                        overflow + " is not a finite number (beyond the range of a double)");
        }
    }

    Result<SceneScript> loadSceneScript(const std::string& path, const GreyImageReader& readImage)
    {
        Result<std::vector<std::uint8_t>> bytes = readFile(path);
        if (!bytes)
            return bytes.error();
        return parseSceneScript(std::string(bytes->begin(), bytes->end()), path,
                                std::filesystem::path(path).parent_path().string(), readImage);
    }

    LightingSpec sceneLighting(const SceneScript& script)
    {
        LightingSpec l;
        l.sunDirection = script.sun.direction;
        l.sunColour = script.sun.colour;
        l.ambientColour = script.sun.ambient;
        return l;
    }
}

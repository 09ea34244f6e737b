// SceneScript: parsing (nlohmann::json for values, a position scan for line/column of
// every key), instance files (CSV, std::from_chars), placements (uniform and Thomas-clustered)
// and the camera path.
//
// This work is based on:
//   M. Thomas, "A generalization of Poisson's binomial limit for use in ecology",
//   Biometrika 36, 1949 (parents uniform, offspring Gaussian around them), the clumped
//   point process of forest ecology; here with a fixed total count instead of Poisson counts.
//   P. J. Barry, R. N. Goldman, "A recursive evaluation algorithm for a class of Catmull-Rom
//   splines", SIGGRAPH 1988, with the centripetal knots of Yuksel, Schaefer, Keyser,
//   "Parameterization and applications of Catmull-Rom curves", CAD 43(7), 2011.
#include "TreeLod/SceneScript.h"

#include "TreeLod/AtomicFile.h"
#include "TreeLod/TreePreset.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <cmath>
#include <filesystem>
#include <string_view>
#include <map>
#include <random>
#include <sstream>

namespace TreeLod
{
    namespace
    {
        using Json = nlohmann::json;
        constexpr double PI = 3.14159265358979323846;
        constexpr std::uint32_t MAX_TREES = 10000000;

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

        /// Internal only: an instance file's error, already naming the CSV file, line and column.
        struct InstanceFileError
        {
            Error error;
        };

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
        /// would silently collapse.
        class PositionScan
        {
        public:
            explicit PositionScan(const std::string& text) : mText(text) {}

            void run() { value(""); }

            std::map<std::string, std::size_t> offsets;

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
                        while (mAt < mText.size() && mText[mAt] != '\n')
                            ++mAt;
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
                        if (mText[mAt++] != ',')
                            return; // '}' or ']'
                    }
                }
                if (c == '"')
                {
                    string();
                    return;
                }
                while (mAt < mText.size() && std::string(",]} \t\r\n/").find(mText[mAt]) == std::string::npos)
                    ++mAt;
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

        std::string formatNumber(double v)
        {
            std::ostringstream out;
            out << v;
            return out.str();
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

        bool excluded(const std::vector<SceneArea>& exclude, const glm::vec2& p)
        {
            for (const SceneArea& e : exclude)
                if (e.contains(p))
                    return true;
            return false;
        }

        /// Area of `area` outside the exclusions, in m²: exact without exclusions, otherwise
        /// the fraction of 512 x 512 cell centres of the bounding box that are free.
        double freeArea(const SceneArea& area, const std::vector<SceneArea>& exclude)
        {
            if (exclude.empty())
                return area.areaM2();
            glm::vec2 lo = area.kind == SceneArea::Kind::Rect ? area.min : area.centre - glm::vec2(area.radius);
            glm::vec2 hi = area.kind == SceneArea::Kind::Rect ? area.max : area.centre + glm::vec2(area.radius);
            const int n = 512;
            std::size_t free = 0;
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x)
                {
                    glm::vec2 p = lo + (hi - lo) * glm::vec2((x + 0.5f) / n, (y + 0.5f) / n);
                    free += area.contains(p) && !excluded(exclude, p);
                }
            return double(hi.x - lo.x) * double(hi.y - lo.y) * double(free) / (double(n) * n);
        }

        // ---- instance files (a placement's "file") -------------------------------------------

        /// A number of an instance file: the whole field (a leading '+' allowed), finite.
        /// Overflow (1e999) and "nan" / "inf" read as not finite; false when it is no number.
        bool csvNumber(std::string_view field, double& out)
        {
            const char* begin = field.data();
            const char* end = begin + field.size();
            if (begin != end && *begin == '+')
                ++begin;
            auto [ptr, ec] = std::from_chars(begin, end, out);
            if (ptr != end || begin == end || ec == std::errc::invalid_argument)
                return false;
            if (ec == std::errc::result_out_of_range) // strtod tells overflow (inf) from underflow (0)
                out = std::strtod(std::string(begin, end).c_str(), nullptr);
            return true;
        }

        std::string_view trimmed(std::string_view s)
        {
            while (!s.empty() && (s.front() == ' ' || s.front() == '\t'))
                s.remove_prefix(1);
            while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
                s.remove_suffix(1);
            return s;
        }

        /// Reads the CSV at `path` into the placement's explicit trees (samples/scenes/README.md,
        /// "Instance files"). Throws InstanceFileError naming the file, line and column.
        void readInstanceFile(const std::string& path, ScenePlacement& p, const SceneScript& script)
        {
            enum Column { X, Z, SPECIES, ROTATION, SCALE, Y, COLUMN_COUNT };
            static const char* const NAMES[COLUMN_COUNT] = {"x", "z", "species", "rotation", "scale", "y"};
            auto failAt = [&](std::size_t line, const std::string& column, const std::string& reason) {
                throw InstanceFileError{fail(path, "line " + std::to_string(line) +
                                                       (column.empty() ? "" : ", column " + column), reason)};
            };
            Result<std::vector<std::uint8_t>> bytes = readFile(path);
            if (!bytes)
                throw InstanceFileError{bytes.error()};
            std::string_view text(reinterpret_cast<const char*>(bytes->data()), bytes->size());
            if (text.substr(0, 3) == "\xEF\xBB\xBF") // a UTF-8 byte order mark
                text.remove_prefix(3);

            const double half = 0.5 * script.ground.size;
            std::vector<Column> columns; // per field of a row
            bool hasSpecies = false, hasY = false;
            std::string columnList;      // "x, z, scale" for messages
            std::string speciesList;     // "oak, pine" for messages
            for (std::uint32_t s : p.species)
                speciesList += (speciesList.empty() ? "" : ", ") + script.species[s].name;
            std::size_t at = 0, line = 0;
            std::string_view fields[COLUMN_COUNT + 1];
            while (at < text.size())
            {
                std::size_t end = text.find('\n', at);
                if (end == std::string_view::npos)
                    end = text.size();
                const std::string_view row = trimmed(text.substr(at, end - at));
                at = end + 1;
                ++line;
                if (row.empty() || row.front() == '#')
                    continue;
                // Split at commas: more fields than columns is an error either way.
                std::size_t count = 0;
                for (std::size_t start = 0;;)
                {
                    const std::size_t comma = row.find(',', start);
                    const std::string_view field =
                        trimmed(row.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
                    if (count <= COLUMN_COUNT)
                        fields[count] = field;
                    ++count;
                    if (comma == std::string_view::npos)
                        break;
                    start = comma + 1;
                }
                if (columns.empty()) // the header
                {
                    bool seen[COLUMN_COUNT] = {};
                    for (std::size_t i = 0; i < count; ++i)
                    {
                        if (i >= COLUMN_COUNT)
                            failAt(line, "", "more columns than x, z, species, rotation, scale, y");
                        const auto known = std::find(std::begin(NAMES), std::end(NAMES), fields[i]);
                        if (known == std::end(NAMES))
                            failAt(line, "", "unknown column '" + std::string(fields[i]) +
                                                 "' (expected x, z and any of species, rotation, scale, y)");
                        const Column c = Column(known - std::begin(NAMES));
                        if (seen[c])
                            failAt(line, "", "column '" + std::string(fields[i]) + "' named twice");
                        seen[c] = true;
                        columns.push_back(c);
                        columnList += (columnList.empty() ? "" : ", ") + std::string(fields[i]);
                    }
                    for (Column c : {X, Z})
                        if (!seen[c])
                            failAt(line, "", std::string("the header lacks the column ") + NAMES[c] +
                                                 " (first line: column names, e.g. x,z,species,rotation,scale)");
                    hasSpecies = seen[SPECIES];
                    hasY = seen[Y];
                    continue;
                }
                if (count != columns.size())
                    failAt(line, "", "expected " + std::to_string(columns.size()) + " columns (" + columnList +
                                         "), got " + std::to_string(count));
                if (p.positions.size() >= MAX_TREES)
                    failAt(line, "", "more than " + std::to_string(MAX_TREES) + " trees");
                glm::vec4 tree(0.0f, 0.0f, 0.0f, 1.0f);
                std::uint32_t species = p.species[0];
                float y = NAN;
                for (std::size_t i = 0; i < count; ++i)
                {
                    const std::string_view f = fields[i];
                    const char* name = NAMES[columns[i]];
                    if (columns[i] == SPECIES)
                    {
                        auto known = std::find_if(p.species.begin(), p.species.end(), [&](std::uint32_t s) {
                            return script.species[s].name == f;
                        });
                        if (known == p.species.end())
                            failAt(line, name, "unknown species '" + std::string(f) + "' (this placement's: " +
                                                   speciesList + ")");
                        species = *known;
                        continue;
                    }
                    double v = 0.0;
                    if (!csvNumber(f, v))
                        failAt(line, name, "'" + std::string(f) + "' is not a number");
                    const std::string shown(f);
                    switch (columns[i])
                    {
                    case X:
                    case Z:
                        if (!std::isfinite(v) || std::abs(v) > half)
                            failAt(line, name, shown + " must be finite and on the ground (|" + name + "| <= " +
                                                   formatNumber(half) + ")");
                        (columns[i] == X ? tree.x : tree.y) = float(v);
                        break;
                    case ROTATION:
                        if (!std::isfinite(v) || std::abs(v) > 360.0)
                            failAt(line, name, shown + " must be finite degrees in [-360, 360]");
                        tree.z = float(v * PI / 180.0);
                        break;
                    case SCALE:
                        if (!std::isfinite(v) || !(v > 0.0))
                            failAt(line, name, shown + " must be finite and > 0");
                        if (v > 1e3)
                            failAt(line, name, shown + " must be <= 1000");
                        tree.w = float(v);
                        break;
                    case Y:
                        if (!std::isfinite(v) || std::abs(v) > 1e6)
                            failAt(line, name, shown + " must be finite metres in [-1e6, 1e6]");
                        y = float(v);
                        break;
                    default:
                        break;
                    }
                }
                p.positions.push_back(tree);
                if (hasSpecies)
                    p.positionSpecies.push_back(species);
                if (hasY)
                    p.positionY.push_back(y);
            }
            if (columns.empty())
                failAt(line, "", "no header line (the first line names the columns, e.g. x,z,species,rotation,scale)");
            if (p.positions.empty())
                failAt(line, "", "no trees (rows after the header)");
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
                glm::vec3 d = vec3(*dir, child(pointer, "direction"));
                if (!(d.y > 0.0f))
                    bad(child(pointer, "direction"), "the sun must be above the horizon (y > 0, towards the sun)");
                sun.direction = glm::normalize(d);
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
                if (s.camera != "focused" && s.camera != "lispsm")
                    bad(child(pointer, "camera"),
                        "unknown shadow camera '" + s.camera + "' (expected focused, lispsm)");
            }
            if (const Json* v = find(j, "lodBias"))
                s.lodBias = float(number(*v, child(pointer, "lodBias"), 0.0, 1e6, true));
            return s;
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
            allowKeys(root, "", {"name", "description", "ground", "species", "placements", "sun", "shadows",
                                 "camera", "resolution", "frames", "counts"});
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
            std::uint64_t explicitTrees = 0;
            bool anyRandom = false;
            for (std::size_t i = 0; i < placements.size(); ++i)
            {
                s.placements.push_back(readPlacement(placements[i], child("/placements", i), s, baseDir));
                explicitTrees += s.placements.back().positions.size();
                anyRandom = anyRandom || s.placements.back().random;
            }

            if (const Json* v = find(root, "sun"))
                s.sun = readSun(*v, "/sun");
            if (const Json* v = find(root, "shadows"))
                s.shadows = readShadows(*v, "/shadows");
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

        // ---- sampling --------------------------------------------------------------------------

        /// Uniform in [0, 1) from two 32-bit draws (53 bits), in a fixed order.
        double uniform(std::mt19937& rng)
        {
            std::uint64_t a = rng() >> 5, b = rng() >> 6;
            return double(a * 67108864ull + b) / 9007199254740992.0;
        }

        /// Standard normal pair by Box-Muller.
        glm::dvec2 gaussian(std::mt19937& rng)
        {
            double u = 1.0 - uniform(rng), v = uniform(rng);
            double r = std::sqrt(-2.0 * std::log(u));
            return glm::dvec2(r * std::cos(2.0 * PI * v), r * std::sin(2.0 * PI * v));
        }

        glm::vec2 uniformIn(const SceneArea& a, std::mt19937& rng)
        {
            double u = uniform(rng), v = uniform(rng);
            if (a.kind == SceneArea::Kind::Rect)
                return glm::vec2(float(a.min.x + u * (a.max.x - a.min.x)), float(a.min.y + v * (a.max.y - a.min.y)));
            double r2 = double(a.innerRadius) * a.innerRadius;
            double r = std::sqrt(r2 + u * (double(a.radius) * a.radius - r2));
            return a.centre + glm::vec2(float(r * std::cos(2.0 * PI * v)), float(r * std::sin(2.0 * PI * v)));
        }

        /// A free point: uniform in the area outside the exclusions (rejection; after 1000
        /// misses, which freeArea() > 0 makes vanishingly rare, the last point is kept).
        glm::vec2 freePoint(const ScenePlacement& p, std::mt19937& rng)
        {
            glm::vec2 q = uniformIn(p.area, rng);
            for (int tries = 0; tries < 1000 && excluded(p.exclude, q); ++tries)
                q = uniformIn(p.area, rng);
            return q;
        }

        /// `n` positions of a random placement. clumping 0: uniform. clumping c > 0: a Thomas
        /// process with a fixed total: k = round(n / (1 + 19c)) cluster centres uniform in the
        /// free area, each tree joins a random cluster and lies at a Gaussian offset of
        /// sigma = (0.25 - 0.1875c) * sqrt(freeArea / k) (a quarter of the cluster spacing at
        /// c -> 0, a sixteenth at c = 1); offsets outside the free area are drawn again.
        std::vector<glm::vec2> samplePositions(const ScenePlacement& p, std::uint32_t n, std::mt19937& rng)
        {
            std::vector<glm::vec2> out;
            out.reserve(n);
            if (p.clumping <= 0.0f)
            {
                for (std::uint32_t i = 0; i < n; ++i)
                    out.push_back(freePoint(p, rng));
                return out;
            }
            const std::uint32_t k =
                std::max<std::uint32_t>(1, std::uint32_t(std::lround(n / (1.0 + 19.0 * p.clumping))));
            // The parser's figure; a placement built in code (freeAreaM2 0) is sampled here.
            const double free = p.freeAreaM2 > 0.0 ? p.freeAreaM2 : freeArea(p.area, p.exclude);
            std::vector<glm::vec2> centres;
            for (std::uint32_t i = 0; i < k; ++i)
                centres.push_back(freePoint(p, rng));
            const double sigma = (0.25 - 0.1875 * p.clumping) * std::sqrt(free / k);
            for (std::uint32_t i = 0; i < n; ++i)
            {
                glm::vec2 q;
                bool placed = false;
                for (int tries = 0; tries < 100 && !placed; ++tries)
                {
                    const glm::vec2& c = centres[std::min<std::uint32_t>(k - 1, std::uint32_t(uniform(rng) * k))];
                    glm::dvec2 g = gaussian(rng) * sigma;
                    q = c + glm::vec2(g);
                    placed = p.area.contains(q) && !excluded(p.exclude, q);
                }
                out.push_back(placed ? q : freePoint(p, rng));
            }
            return out;
        }

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

    bool SceneArea::contains(const glm::vec2& p) const
    {
        if (kind == Kind::Rect)
            return p.x >= min.x && p.x <= max.x && p.y >= min.y && p.y <= max.y;
        float d = glm::length(p - centre);
        return d <= radius && d >= innerRadius;
    }

    float SceneArea::areaM2() const
    {
        if (kind == Kind::Rect)
            return (max.x - min.x) * (max.y - min.y);
        return float(PI * (double(radius) * radius - double(innerRadius) * innerRadius));
    }

    Result<SceneScript> parseSceneScript(const std::string& text, const std::string& label, const std::string& baseDir,
                                         const GreyImageReader& readImage)
    {
        Json root;
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
        PositionScan scan(text);
        try
        {
            scan.run();
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
    }

    Result<SceneScript> loadSceneScript(const std::string& path, const GreyImageReader& readImage)
    {
        Result<std::vector<std::uint8_t>> bytes = readFile(path);
        if (!bytes)
            return bytes.error();
        return parseSceneScript(std::string(bytes->begin(), bytes->end()), path,
                                std::filesystem::path(path).parent_path().string(), readImage);
    }

    float groundHeight(const SceneGround& ground, float x, float z)
    {
        if (ground.kind == SceneGround::Kind::Plane || ground.heights.empty())
            return 0.0f;
        const int w = ground.heightsWidth, h = ground.heightsHeight;
        float u = glm::clamp((x / ground.size + 0.5f) * float(w - 1), 0.0f, float(w - 1));
        float v = glm::clamp((z / ground.size + 0.5f) * float(h - 1), 0.0f, float(h - 1));
        int x0 = std::min(int(u), w - 2), y0 = std::min(int(v), h - 2);
        float fx = u - float(x0), fy = v - float(y0);
        auto at = [&](int px, int py) { return ground.heights[std::size_t(py) * w + px]; };
        float top = at(x0, y0) + fx * (at(x0 + 1, y0) - at(x0, y0));
        float bottom = at(x0, y0 + 1) + fx * (at(x0 + 1, y0 + 1) - at(x0, y0 + 1));
        return ground.heightScale * (top + fy * (bottom - top));
    }

    std::vector<PlacedTree> generatePlacements(const SceneScript& script, const PlacementOptions& options)
    {
        // Tree counts per placement: explicit ones as listed, random ones from the script,
        // then the total (largest remainder over the random placements), then the scale.
        std::vector<std::uint64_t> counts;
        std::uint64_t explicitTotal = 0, randomTotal = 0;
        for (const ScenePlacement& p : script.placements)
        {
            counts.push_back(p.random ? p.count : p.positions.size());
            (p.random ? randomTotal : explicitTotal) += counts.back();
        }
        if (options.totalCount > 0)
        {
            std::uint64_t keepExplicit = std::min<std::uint64_t>(options.totalCount, explicitTotal);
            std::uint64_t wantRandom = options.totalCount - keepExplicit;
            std::vector<std::pair<double, std::size_t>> remainders;
            std::uint64_t given = 0;
            for (std::size_t i = 0; i < counts.size(); ++i)
            {
                if (script.placements[i].random)
                {
                    double exact = randomTotal ? double(wantRandom) * double(counts[i]) / double(randomTotal) : 0.0;
                    counts[i] = std::uint64_t(exact);
                    given += counts[i];
                    remainders.emplace_back(-(exact - std::floor(exact)), i); // largest first, then script order
                }
                else
                {
                    counts[i] = std::min<std::uint64_t>(counts[i], keepExplicit);
                    keepExplicit -= counts[i];
                }
            }
            std::sort(remainders.begin(), remainders.end());
            for (std::size_t r = 0; given < wantRandom && r < remainders.size(); ++r, ++given)
                ++counts[remainders[r].second];
        }
        if (options.scale != 1.0 && options.scale > 0.0)
            for (std::size_t i = 0; i < counts.size(); ++i)
                if (script.placements[i].random && counts[i] > 0)
                    counts[i] =
                        std::max<std::uint64_t>(1, std::uint64_t(std::llround(double(counts[i]) * options.scale)));

        std::vector<PlacedTree> trees;
        // Explicit placements first, then random ones, each in script order.
        for (int pass = 0; pass < 2; ++pass)
            for (std::size_t i = 0; i < script.placements.size(); ++i)
            {
                const ScenePlacement& p = script.placements[i];
                if (p.random != (pass == 1))
                    continue;
                if (!p.random)
                {
                    for (std::size_t k = 0; k < counts[i]; ++k)
                    {
                        const glm::vec4& e = p.positions[k];
                        const float y = p.positionY.empty() || std::isnan(p.positionY[k])
                                            ? groundHeight(script.ground, e.x, e.y)
                                            : p.positionY[k];
                        trees.push_back({p.positionSpecies.empty() ? p.species[0] : p.positionSpecies[k],
                                         glm::vec3(e.x, y, e.y), e.z, e.w});
                    }
                    continue;
                }
                std::mt19937 rng(p.seed);
                std::vector<glm::vec2> positions = samplePositions(p, std::uint32_t(counts[i]), rng);
                for (const glm::vec2& q : positions)
                {
                    PlacedTree t;
                    t.species = p.species[std::min<std::size_t>(p.species.size() - 1,
                                                                std::size_t(uniform(rng) * p.species.size()))];
                    t.position = glm::vec3(q.x, groundHeight(script.ground, q.x, q.y), q.y);
                    t.rotation = float(uniform(rng) * 2.0 * PI);
                    const SceneSpecies& s = script.species[t.species];
                    t.scale = float(s.scaleMin + uniform(rng) * (s.scaleMax - s.scaleMin));
                    trees.push_back(t);
                }
            }
        return trees;
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

    LightingSpec sceneLighting(const SceneScript& script)
    {
        LightingSpec l;
        l.sunDirection = script.sun.direction;
        l.sunColour = script.sun.colour;
        l.ambientColour = script.sun.ambient;
        return l;
    }
}

// Instance files (a placement's "file"): one read of the CSV, std::from_chars per number.
#include "InstanceFile.h"

#include "SceneScriptDetail.h"
#include "TreeLod/AtomicFile.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <string_view>

namespace TreeLod::SceneScriptDetail
{
    namespace
    {
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
    }

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
}

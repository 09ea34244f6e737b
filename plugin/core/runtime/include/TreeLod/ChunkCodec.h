// ChunkCodec: what the chunk formats' encoders and decoders share, on top of ByteWriter and
// ByteReader: the flags word, counted arrays (count limits, alignment, per-record checks) and
// the standard error texts. A record's fields are listed once, as a generic lambda over the
// stream, for both directions (ByteWriter::fields / ByteReader::fields):
//
//   constexpr ArrayLayout LEVELS{LEVEL_BYTES, 1, 1, MAX_LEVELS, "levels"};
//   const auto levelFields = [](auto& s, auto& l) { s.fields(l.first, l.count, l.scale); };
//   encode:   w.u32(KNOWN_FLAGS); writeArray(w, data.levels, LEVELS, levelFields);
//   decode:   readFlags(r, KNOWN_FLAGS); readArray(r, data.levels, LEVELS, levelFields);
//             return finishDecode(r, label, name, std::move(data));
//   validate: LEVELS.countProblem(levels.size())
//
// The add<X>Chunk glue (bake, encode, PackageWriter::addChunk) is addBakedChunk in PackageWriter.h.
#pragma once

#include "TreeLod/ByteReader.h"
#include "TreeLod/ByteWriter.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

namespace TreeLod
{
    /// How an array is stored: u32 count, zero bytes up to `alignment`, the records.
    struct ArrayLayout
    {
        /// The least bytes a record takes: readArray refuses a count whose records cannot fit
        /// in the bytes left before it allocates anything.
        std::size_t recordBytes = 0;
        std::size_t alignment = 1;          ///< the records start at a multiple of this from the chunk start
        std::uint32_t minCount = 0;         ///< counts allowed, [minCount, maxCount]
        std::uint32_t maxCount = 0xffffffffu;
        const char* noun = "records";       ///< the records in count errors

        /// "40 levels (1 to 32 needed)" when `count` is outside [minCount, maxCount], else "".
        std::string countProblem(std::uint64_t count) const
        {
            if (count >= minCount && count <= maxCount)
                return {};
            return std::to_string(count) + " " + noun + " (" + std::to_string(minCount) + " to " +
                   std::to_string(maxCount) + " needed)";
        }
    };

    /// Record "unknown flags N" (the reader's current element) when `flags` has a bit outside
    /// `known`; returns `flags`.
    inline std::uint32_t checkFlags(ByteReader& r, std::uint32_t flags, std::uint32_t known)
    {
        if (r.ok() && (flags & ~known) != 0)
            r.failHere("unknown flags " + std::to_string(flags));
        return flags;
    }

    /// A u32 flags word, checked against `known`.
    inline std::uint32_t readFlags(ByteReader& r, std::uint32_t known) { return checkFlags(r, r.u32(), known); }

    /// `records` in `layout`; `write(w, record)` writes one.
    template <typename T, typename Write>
    void writeArray(ByteWriter& w, const std::vector<T>& records, const ArrayLayout& layout, Write write)
    {
        w.u32(std::uint32_t(records.size()));
        w.align(layout.alignment);
        w.reserve(records.size() * layout.recordBytes);
        for (const T& record : records)
            write(w, record);
    }

    /// An array in `layout` into `records`: the count is checked against the bytes left and
    /// layout's limits (errors name the reader's current element), then `read(r, record)` or
    /// `read(r, record, index)` reads each record and may fail it (ByteReader::failHere), which
    /// stops the reading. False with the reader's error set.
    template <typename T, typename Read>
    bool readArray(ByteReader& r, std::vector<T>& records, const ArrayLayout& layout, Read read)
    {
        const std::uint32_t count = r.count(layout.recordBytes, layout.alignment);
        if (r.ok())
            if (std::string problem = layout.countProblem(count); !problem.empty())
                r.failHere(problem);
        r.align(layout.alignment);
        if (!r.ok())
            return false;
        records.resize(count);
        for (std::uint32_t i = 0; i < count && r.ok(); ++i)
        {
            if constexpr (std::is_invocable_v<Read&, ByteReader&, T&, std::uint32_t>)
                read(r, records[i], i);
            else
                read(r, records[i]);
        }
        return r.ok();
    }
}

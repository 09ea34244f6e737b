// ByteWriter: builds the little-endian byte layout of a package chunk (Package.h).
// The counterpart of ByteReader; every chunk format encodes with it (arrays and flags: ChunkCodec.h).
#pragma once

#include <glm/glm.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace TreeLod
{
    class ByteWriter
    {
    public:
        void u8(std::uint8_t v) { mBytes.push_back(v); }
        void u16(std::uint16_t v) { little(v, 2); }
        void u32(std::uint32_t v) { little(v, 4); }
        void i32(std::int32_t v) { little(std::uint32_t(v), 4); }
        void u64(std::uint64_t v) { little(v, 8); }
        void f32(float v)
        {
            std::uint32_t bits;
            std::memcpy(&bits, &v, 4);
            u32(bits);
        }
        void vec2(const glm::vec2& v)
        {
            f32(v.x);
            f32(v.y);
        }
        void vec3(const glm::vec3& v)
        {
            vec2(glm::vec2(v));
            f32(v.z);
        }
        void vec4(const glm::vec4& v)
        {
            vec3(glm::vec3(v));
            f32(v.w);
        }

        /// Each value in the layout of its type (u8, u16, u32, i32, u64, f32, vec2, vec3, vec4), in
        /// order: with ByteReader::fields, one list of a record's fields serves both directions.
        template <typename... T> void fields(const T&... values) { (field(values), ...); }

        /// u32 byte length, then the bytes (no terminator).
        void string(const std::string& s)
        {
            u32(std::uint32_t(s.size()));
            bytes(s.data(), s.size());
        }

        void bytes(const void* data, std::size_t size)
        {
            const auto* p = static_cast<const std::uint8_t*>(data);
            mBytes.insert(mBytes.end(), p, p + size);
        }

        /// Zero bytes up to the next multiple of `alignment` from the start.
        void align(std::size_t alignment)
        {
            while (mBytes.size() % alignment != 0)
                mBytes.push_back(0);
        }

        /// Make room for `size` more bytes (no change to the content).
        void reserve(std::size_t size) { mBytes.reserve(mBytes.size() + size); }

        std::size_t size() const { return mBytes.size(); }
        const std::vector<std::uint8_t>& data() const { return mBytes; }
        std::vector<std::uint8_t> take() { return std::move(mBytes); }

    private:
        void field(std::uint8_t v) { u8(v); }
        void field(std::uint16_t v) { u16(v); }
        void field(std::uint32_t v) { u32(v); }
        void field(std::int32_t v) { i32(v); }
        void field(std::uint64_t v) { u64(v); }
        void field(float v) { f32(v); }
        void field(const glm::vec2& v) { vec2(v); }
        void field(const glm::vec3& v) { vec3(v); }
        void field(const glm::vec4& v) { vec4(v); }
        /// No conversions: a value of another type has no stored layout.
        template <typename T> void field(const T&) = delete;

        void little(std::uint64_t v, int n)
        {
            for (int i = 0; i < n; ++i)
                mBytes.push_back(std::uint8_t(v >> (8 * i)));
        }

        std::vector<std::uint8_t> mBytes;
    };
}

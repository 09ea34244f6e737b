// ByteReader: bounds-checked little-endian reads from untrusted bytes (package chunks).
//
// Errors are sticky: the first failed read records an Error (file, current element,
// "truncated: needs 32 bytes at offset 120, chunk has 128") and every later read returns
// zeros, so a decoder may read a whole record and check ok() once. count() checks a
// declared element count against the bytes left before the caller allocates, which bounds
// the memory a hostile input can make a decoder take to a small multiple of its size.
// Arrays, flags and their standard errors: ChunkCodec.h.
#pragma once

#include "TreeLod/Result.h"

#include <glm/glm.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>

namespace TreeLod
{
    class ByteReader
    {
    public:
        /// `data` must outlive the reader. `file` and `element` label errors; `container`
        /// names the whole range in "truncated" messages ("chunk", "file").
        ByteReader(const std::uint8_t* data, std::size_t size, std::string file, std::string element,
                   std::string container = "chunk")
            : mData(data), mSize(size), mFile(std::move(file)), mElement(std::move(element)),
              mContainer(std::move(container))
        {
        }

        /// The element named by errors from now on ("texture 2 'leaf'").
        void setElement(std::string element) { mElement = std::move(element); }
        const std::string& element() const { return mElement; }

        std::uint8_t u8() { return std::uint8_t(little(1)); }
        std::uint16_t u16() { return std::uint16_t(little(2)); }
        std::uint32_t u32() { return std::uint32_t(little(4)); }
        std::int32_t i32() { return std::int32_t(std::uint32_t(little(4))); }
        std::uint64_t u64() { return little(8); }
        float f32()
        {
            std::uint32_t bits = u32();
            float v;
            std::memcpy(&v, &bits, 4);
            return v;
        }
        glm::vec2 vec2()
        {
            float x = f32(), y = f32();
            return {x, y};
        }
        glm::vec3 vec3()
        {
            float x = f32(), y = f32(), z = f32();
            return {x, y, z};
        }
        glm::vec4 vec4()
        {
            float x = f32(), y = f32(), z = f32(), w = f32();
            return {x, y, z, w};
        }

        /// Each value in the layout of its type (ByteWriter::fields), in order.
        template <typename... T> void fields(T&... values) { (field(values), ...); }

        /// u32 byte length + bytes; fails if longer than `maxLength`.
        std::string string(std::size_t maxLength = 4096)
        {
            std::uint32_t n = u32();
            if (!ok())
                return {};
            if (n > maxLength)
            {
                failHere("string of " + std::to_string(n) + " bytes, at most " + std::to_string(maxLength) +
                         " allowed");
                return {};
            }
            const std::uint8_t* p = take(n);
            return p ? std::string(reinterpret_cast<const char*>(p), n) : std::string();
        }

        /// Pointer to the next `size` bytes, advancing past them; null (and an error) if fewer remain.
        const std::uint8_t* take(std::size_t size)
        {
            if (!ok())
                return nullptr;
            if (size > mSize - mOffset)
            {
                failHere("truncated: needs " + std::to_string(size) + " bytes at offset " + std::to_string(mOffset) +
                         ", " + mContainer + " has " + std::to_string(mSize));
                return nullptr;
            }
            const std::uint8_t* p = mData + mOffset;
            mOffset += size;
            return p;
        }

        /// A u32 element count whose elements take at least `elementBytes` each: 0 (and an
        /// error) if that many cannot fit in the rest, so the caller can allocate safely.
        std::uint32_t count(std::size_t elementBytes, std::size_t alignment = 1)
        {
            const std::size_t at = mOffset;
            std::uint32_t n = u32();
            if (!ok())
                return 0;
            std::size_t padding = (alignment - mOffset % alignment) % alignment;
            std::size_t left = mSize - mOffset;
            if (elementBytes > 0 && (padding > left || n > (left - padding) / elementBytes))
            {
                failHere("count " + std::to_string(n) + " at offset " + std::to_string(at) + " needs " +
                         std::to_string(std::uint64_t(n) * elementBytes) + " bytes, " + mContainer + " has " +
                         std::to_string(left) + " left");
                return 0;
            }
            return n;
        }

        /// Skip to the next multiple of `alignment` from the start.
        void align(std::size_t alignment) { take((alignment - mOffset % alignment) % alignment); }

        /// Record `reason` for the current element unless an error is already recorded.
        void failHere(const std::string& reason)
        {
            if (ok())
            {
                mError = Error{mFile, mElement, reason};
                mFailed = true;
            }
        }

        bool ok() const { return !mFailed; }
        const Error& error() const { return mError; }
        std::size_t offset() const { return mOffset; }
        std::size_t remaining() const { return mSize - mOffset; }

    private:
        void field(std::uint8_t& v) { v = u8(); }
        void field(std::uint16_t& v) { v = u16(); }
        void field(std::uint32_t& v) { v = u32(); }
        void field(std::int32_t& v) { v = i32(); }
        void field(std::uint64_t& v) { v = u64(); }
        void field(float& v) { v = f32(); }
        void field(glm::vec2& v) { v = vec2(); }
        void field(glm::vec3& v) { v = vec3(); }
        void field(glm::vec4& v) { v = vec4(); }

        std::uint64_t little(int n)
        {
            const std::uint8_t* p = take(std::size_t(n));
            std::uint64_t v = 0;
            if (p)
                for (int i = 0; i < n; ++i)
                    v |= std::uint64_t(p[i]) << (8 * i);
            return v;
        }

        const std::uint8_t* mData;
        std::size_t mSize;
        std::size_t mOffset = 0;
        std::string mFile;
        std::string mElement;
        std::string mContainer;
        bool mFailed = false;
        Error mError;
    };

    /// The end of a chunk decoder: `r`'s error; "N trailing bytes" (file `file`, element
    /// `element`) when `r` has not read every byte; the error of `data.validate(file)`; else `data`.
    template <typename T>
    Result<T> finishDecode(const ByteReader& r, const std::string& file, const std::string& element, T data)
    {
        if (!r.ok())
            return r.error();
        if (r.remaining() != 0)
            return fail(file, element, std::to_string(r.remaining()) + " trailing bytes");
        Result<void> valid = data.validate(file);
        if (!valid)
            return valid.error();
        return Result<T>(std::move(data));
    }
}

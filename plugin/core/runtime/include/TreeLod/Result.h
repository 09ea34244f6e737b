// Result<T>: the outcome of a core function that can fail on its input.
//
// Contract (docs/architecture.md, "Errors"): a failure carries the file, the element
// (node, mesh, primitive, chunk, pixel...) and the reason, so the caller can print
// "file: element: reason" and stop. Results never throw; the CLI exits 2 on one.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <variant>

namespace TreeLod
{
    /// What went wrong and where. Any field may be empty except reason.
    struct Error
    {
        std::string file;    ///< input or output path, "" for in-memory data
        std::string element; ///< e.g. "mesh 3 'Leaves' primitive 0", "chunk 'REF0'"
        std::string reason;  ///< e.g. "index 4711 out of range (1024 vertices)"

        /// "file: element: reason", skipping empty parts.
        std::string message() const
        {
            std::string out;
            if (!file.empty())
                out += file + ": ";
            if (!element.empty())
                out += element + ": ";
            return out + reason;
        }
    };

    /// Either a value or an Error. Result<void> carries only the error.
    template <typename T> class Result
    {
    public:
        Result(T value) : mData(std::move(value)) {}
        Result(Error error) : mData(std::move(error)) {}

        bool ok() const { return mData.index() == 0; }
        explicit operator bool() const { return ok(); }

        T& value() & { return std::get<0>(mData); }
        const T& value() const& { return std::get<0>(mData); }
        T&& value() && { return std::get<0>(std::move(mData)); }
        T* operator->() { return &value(); }
        const T* operator->() const { return &value(); }
        T& operator*() & { return value(); }
        const T& operator*() const& { return value(); }

        const Error& error() const { return std::get<1>(mData); }

    private:
        std::variant<T, Error> mData;
    };

    template <> class Result<void>
    {
    public:
        Result() = default;
        Result(Error error) : mError(std::move(error)) {}

        bool ok() const { return !mError.has_value(); }
        explicit operator bool() const { return ok(); }
        const Error& error() const { return *mError; }

    private:
        std::optional<Error> mError;
    };

    /// Shorthand for returning a failure: `return fail(path, "node 3", "NaN in matrix");`
    inline Error fail(std::string file, std::string element, std::string reason)
    {
        return Error{std::move(file), std::move(element), std::move(reason)};
    }
}

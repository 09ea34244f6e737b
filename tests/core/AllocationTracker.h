// AllocationTracker: the largest single allocation a piece of code makes, to show that hostile
// input (a count or size claiming gigabytes) is refused before anything of that size is asked for.
//
// AllocationTracker.cpp replaces the global operator new and delete (every form) and malloc,
// calloc, realloc, aligned_alloc and posix_memalign (the C image decoders allocate with these),
// on glibc and without a sanitizer (which brings its own); elsewhere available() is false and
// nothing is recorded. Link it into a test binary to use this header; it records only while a
// tracker is alive and changes nothing else.
#pragma once

#include <cstddef>

namespace TreeLod
{
    namespace test
    {
        class AllocationTracker
        {
        public:
            /// Starts recording (from zero); one tracker at a time, any thread's allocations count.
            AllocationTracker();
            /// Stops recording.
            ~AllocationTracker();
            AllocationTracker(const AllocationTracker&) = delete;
            AllocationTracker& operator=(const AllocationTracker&) = delete;

            /// Bytes of the largest single allocation since construction.
            std::size_t largest() const;

            /// False where this build cannot track (not glibc, or a sanitizer): largest() stays 0.
            static bool available();
        };
    }
}

// Replacements of operator new / delete and of malloc and its relatives that record the largest
// single request while an AllocationTracker is alive. They allocate with glibc's own functions
// (__libc_malloc and friends, which glibc exports for exactly this), so memory from either side
// may be freed by the other.
#include "AllocationTracker.h"

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <new>

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(memory_sanitizer) || __has_feature(thread_sanitizer)
#define TREELOD_SANITIZED 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define TREELOD_SANITIZED 1
#endif
#if defined(__GLIBC__) && !defined(TREELOD_SANITIZED)
#define TREELOD_TRACK_ALLOCATIONS 1
#endif

namespace
{
    std::atomic<bool> gActive{false};
    std::atomic<std::size_t> gLargest{0};

#ifdef TREELOD_TRACK_ALLOCATIONS
    void record(std::size_t size)
    {
        if (!gActive.load(std::memory_order_relaxed))
            return;
        std::size_t seen = gLargest.load(std::memory_order_relaxed);
        while (size > seen && !gLargest.compare_exchange_weak(seen, size, std::memory_order_relaxed))
        {
        }
    }
#endif
}

namespace TreeLod
{
    namespace test
    {
        AllocationTracker::AllocationTracker()
        {
            gLargest.store(0);
            gActive.store(true);
        }

        AllocationTracker::~AllocationTracker() { gActive.store(false); }

        std::size_t AllocationTracker::largest() const { return gLargest.load(); }

        bool AllocationTracker::available()
        {
#ifdef TREELOD_TRACK_ALLOCATIONS
            return true;
#else
            return false;
#endif
        }
    }
}

#ifdef TREELOD_TRACK_ALLOCATIONS

extern "C"
{
    void* __libc_malloc(std::size_t size);
    void* __libc_calloc(std::size_t count, std::size_t size);
    void* __libc_realloc(void* p, std::size_t size);
    void* __libc_memalign(std::size_t alignment, std::size_t size);
    void __libc_free(void* p);

    void* malloc(std::size_t size) noexcept
    {
        record(size);
        return __libc_malloc(size);
    }

    void* calloc(std::size_t count, std::size_t size) noexcept
    {
        // An overflowing product is refused by glibc; record the most a size_t can say.
        record(size != 0 && count > std::size_t(-1) / size ? std::size_t(-1) : count * size);
        return __libc_calloc(count, size);
    }

    void* realloc(void* p, std::size_t size) noexcept
    {
        record(size);
        return __libc_realloc(p, size);
    }

    void free(void* p) noexcept { __libc_free(p); }

    void* aligned_alloc(std::size_t alignment, std::size_t size) noexcept
    {
        record(size);
        return __libc_memalign(alignment, size);
    }

    int posix_memalign(void** out, std::size_t alignment, std::size_t size) noexcept
    {
        if (alignment == 0 || alignment % sizeof(void*) != 0 || (alignment & (alignment - 1)) != 0)
            return EINVAL;
        record(size);
        void* p = __libc_memalign(alignment, size);
        if (!p)
            return ENOMEM;
        *out = p;
        return 0;
    }
}

namespace
{
    void* allocate(std::size_t size, std::size_t alignment)
    {
        if (size == 0)
            size = 1;
        record(size);
        for (;;)
        {
            void* p = alignment > alignof(std::max_align_t) ? __libc_memalign(alignment, size) : __libc_malloc(size);
            if (p)
                return p;
            std::new_handler handler = std::get_new_handler();
            if (!handler)
                throw std::bad_alloc();
            handler();
        }
    }

    void* allocateNoThrow(std::size_t size, std::size_t alignment) noexcept
    {
        try
        {
            return allocate(size, alignment);
        }
        catch (...)
        {
            return nullptr;
        }
    }
}

void* operator new(std::size_t size) { return allocate(size, 0); }
void* operator new[](std::size_t size) { return allocate(size, 0); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return allocateNoThrow(size, 0); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return allocateNoThrow(size, 0); }
void* operator new(std::size_t size, std::align_val_t a) { return allocate(size, std::size_t(a)); }
void* operator new[](std::size_t size, std::align_val_t a) { return allocate(size, std::size_t(a)); }
void* operator new(std::size_t size, std::align_val_t a, const std::nothrow_t&) noexcept
{
    return allocateNoThrow(size, std::size_t(a));
}
void* operator new[](std::size_t size, std::align_val_t a, const std::nothrow_t&) noexcept
{
    return allocateNoThrow(size, std::size_t(a));
}

void operator delete(void* p) noexcept { __libc_free(p); }
void operator delete[](void* p) noexcept { __libc_free(p); }
void operator delete(void* p, std::size_t) noexcept { __libc_free(p); }
void operator delete[](void* p, std::size_t) noexcept { __libc_free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { __libc_free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { __libc_free(p); }
void operator delete(void* p, std::align_val_t) noexcept { __libc_free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { __libc_free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { __libc_free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { __libc_free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { __libc_free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { __libc_free(p); }

#endif

// Transparent huge pages for the large arrays of a run (the stiffness matrix, its block copies,
// the multigrid's products): one page fault per 2 MB instead of one per 4 KB where the kernel
// hands out huge pages only on request (THP "madvise", the default of Debian and Ubuntu).
#pragma once
#include <cstddef>

namespace topopt {

/// Allocations of at least this many bytes get the huge-page advice (advise_huge_pages); below
/// it at most one 2 MB page fits inside a block anyway.
constexpr std::size_t kHugePageAdviceBytes = std::size_t{4} << 20;

/// Asks the kernel to back the 2 MB-aligned pages inside [p, p + bytes) with transparent huge
/// pages when they are first touched (madvise MADV_HUGEPAGE). p: the start of a block of
/// `bytes` bytes this process owns (e.g. from malloc). Advice only: nothing changes where the
/// kernel has no huge pages or THP is off ("never"), or off Linux. The block's first and last
/// partial 2 MB are left alone (they may share a huge page with other blocks).
void advise_huge_pages(void* p, std::size_t bytes);

/// malloc and calloc, with the huge-page advice for a block of kHugePageAdviceBytes or more
/// (the executables' operator new, and CHOLMOD's allocations in them: the coarse multigrid
/// level's factor). Null where malloc / calloc return null.
void* malloc_advised(std::size_t bytes);
void* calloc_advised(std::size_t count, std::size_t size);

}  // namespace topopt

// Transparent huge pages for large arrays (see huge_pages.h).
#include "common/huge_pages.h"

#include <cstdint>
#include <cstdlib>

#ifdef __linux__
#include <sys/mman.h>
#endif

namespace topopt {

void advise_huge_pages(void* p, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr std::uintptr_t kHuge = std::uintptr_t{2} << 20;
  const std::uintptr_t start = reinterpret_cast<std::uintptr_t>(p);
  const std::uintptr_t begin = (start + kHuge - 1) & ~(kHuge - 1), end = (start + bytes) & ~(kHuge - 1);
  if (end > begin) ::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);  // advice: errors ignored
#else
  (void)p, (void)bytes;
#endif
}

void* malloc_advised(std::size_t bytes) {
  void* p = std::malloc(bytes);
  if (p && bytes >= kHugePageAdviceBytes) advise_huge_pages(p, bytes);
  return p;
}

void* calloc_advised(std::size_t count, std::size_t size) {
  // a large block comes fresh from mmap, untouched (calloc does not clear what the kernel
  // zeroes), so the advice still comes before its first touch
  void* p = std::calloc(count, size);
  if (p && size && count >= kHugePageAdviceBytes / size) advise_huge_pages(p, count * size);
  return p;
}

}  // namespace topopt

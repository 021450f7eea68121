// The command-line tool's operator new: malloc as the default one, and for a block of
// kHugePageAdviceBytes or more the huge-page advice (common/huge_pages.h) before anything
// touches it. On the 2-core EPYC VM of BENCHMARKS.md a 4 KB page fault costs ~6 µs: the rocker's
// one solve (280 MB peak) took 75 000 of them, a third of its CPU. Only the executables replace
// operator new (this file is not in topopt_core): the Python module inside FreeCAD keeps the
// process's own. Eigen and CHOLMOD allocate with malloc and are not concerned.
#include <cstdlib>
#include <new>

#include "common/huge_pages.h"

void* operator new(std::size_t bytes) {
  void* p = std::malloc(bytes ? bytes : 1);
  if (!p) throw std::bad_alloc();
  if (bytes >= topopt::kHugePageAdviceBytes) topopt::advise_huge_pages(p, bytes);
  return p;
}

void* operator new[](std::size_t bytes) { return ::operator new(bytes); }

void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

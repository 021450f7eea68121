// The command-line tool's operator new: malloc as the default one, and for a block of
// kHugePageAdviceBytes or more the huge-page advice (common/huge_pages.h) before anything
// touches it. On the 2-core EPYC VM of BENCHMARKS.md a 4 KB page fault costs ~6 µs: the rocker's
// one solve (280 MB peak) took 75 000 of them, a third of its CPU. Only the executables replace
// operator new (this file is not in topopt_core): the Python module inside FreeCAD keeps the
// process's own. CHOLMOD's malloc and calloc get the same advice (use_huge_pages_in_cholmod,
// called by main: the coarse multigrid level's factor, ~25 % of the solve's faults once K's
// arrays had huge pages); Eigen's own vectors use malloc as they are.
#include <SuiteSparse_config.h>

#include <cstdlib>
#include <new>

#include "cli/commands.h"
#include "common/huge_pages.h"

// As the standard's: on failure the installed new-handler runs (it may free memory) and the
// allocation is tried again; with none installed, std::bad_alloc.
void* operator new(std::size_t bytes) {
  for (;;) {
    if (void* p = topopt::malloc_advised(bytes ? bytes : 1)) return p;
    const std::new_handler handler = std::get_new_handler();
    if (!handler) throw std::bad_alloc();
    handler();
  }
}

void* operator new[](std::size_t bytes) { return ::operator new(bytes); }

void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace topopt::cli {

void use_huge_pages_in_cholmod() {
  SuiteSparse_config.malloc_func = malloc_advised;
  SuiteSparse_config.calloc_func = calloc_advised;
}

}  // namespace topopt::cli

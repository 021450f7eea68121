// Scoped switch of the floating-point unit to flush subnormal numbers to zero.
//
// Why: with SIMP's 1e-9 void stiffness, the fill entries of a Cholesky factor decay through
// void regions into the subnormal range (below 2.2e-308), where every operation costs about
// 100 times more; flushing them made the factorisation 4 times faster (fem/direct_solver.cpp).
// The switch is a control register of the calling thread (x86: MXCSR's FTZ and DAZ bits;
// AArch64: FPCR.FZ), so it must be undone on every way out of the scope: hence a guard.
#pragma once
#include <cstdint>

#if defined(__SSE2__) || defined(_M_X64)
#include <xmmintrin.h>
#define TOPOPT_FLUSH_SUBNORMALS_X86 1
#elif defined(__aarch64__)
#define TOPOPT_FLUSH_SUBNORMALS_AARCH64 1
#endif

namespace topopt {

/// While alive, the calling thread treats subnormal operands and results as zero; its previous
/// mode is restored when the guard dies, also when an exception leaves the scope. Other
/// threads (a multithreaded BLAS's workers) keep their own mode. On a target without such a
/// switch the guard does nothing: results then keep their subnormals (the same to round-off,
/// only slower). Guards nest (each restores what it found).
class FlushSubnormals {
 public:
  FlushSubnormals() : saved_(read()) { write(saved_ | kFlushBits); }
  ~FlushSubnormals() { write(saved_); }
  FlushSubnormals(const FlushSubnormals&) = delete;
  FlushSubnormals& operator=(const FlushSubnormals&) = delete;

  /// True if this target has the switch (else the guard is a no-op).
  static constexpr bool supported() { return kFlushBits != 0; }

 private:
#if defined(TOPOPT_FLUSH_SUBNORMALS_X86)
  static constexpr std::uint64_t kFlushBits = 0x8040;  // FTZ (bit 15) | DAZ (bit 6)
  static std::uint64_t read() { return _mm_getcsr(); }
  static void write(std::uint64_t mode) { _mm_setcsr(static_cast<unsigned>(mode)); }
#elif defined(TOPOPT_FLUSH_SUBNORMALS_AARCH64)
  static constexpr std::uint64_t kFlushBits = std::uint64_t(1) << 24;  // FPCR.FZ
  static std::uint64_t read() {
    std::uint64_t mode;
    __asm__ __volatile__("mrs %0, fpcr" : "=r"(mode));
    return mode;
  }
  static void write(std::uint64_t mode) { __asm__ __volatile__("msr fpcr, %0" : : "r"(mode)); }
#else
  static constexpr std::uint64_t kFlushBits = 0;
  static std::uint64_t read() { return 0; }
  static void write(std::uint64_t) {}
#endif
  std::uint64_t saved_;
};

}  // namespace topopt

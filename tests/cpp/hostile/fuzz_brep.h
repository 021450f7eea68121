// Deterministic damage to BREP text for the hostile-input suites: the same seed gives the
// same damaged text on every machine (splitmix64, no library distribution), and
// tests/python/app/test_hostile_input.py makes the same cases in Python.
#pragma once
#include <cstdint>
#include <string>

namespace topopt::testing {

/// The kinds of damage: byte flips, inserted bytes, deleted runs, truncation, and digits
/// changed to other digits (damage that keeps the text well-formed: wrong indices, counts).
enum class Damage { Flip = 0, Insert = 1, Delete = 2, Truncate = 3, Digit = 4 };

/// splitmix64: the next value of the generator whose state is `s`.
inline uint64_t next_random(uint64_t& s) {
  uint64_t z = (s += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

/// `text` (not empty) damaged by `kind`, the positions and bytes drawn from `seed`:
/// Flip: 1-4 bytes xor-ed with 1..255; Insert: 1-8 random bytes at one place; Delete: a run
/// of 1-16 bytes; Truncate: cut at a random length; Digit: 1-3 digits each replaced by another.
inline std::string damage_brep(const std::string& text, Damage kind, uint64_t seed) {
  uint64_t s = seed * 1000003ULL + static_cast<uint64_t>(kind);
  std::string t = text;
  auto pick = [&](uint64_t n) { return static_cast<size_t>(next_random(s) % n); };
  switch (kind) {
    case Damage::Flip:
      for (size_t i = 0, n = 1 + pick(4); i < n; ++i) {
        const size_t p = pick(t.size());
        t[p] = static_cast<char>(static_cast<unsigned char>(t[p]) ^ (1 + pick(255)));
      }
      break;
    case Damage::Insert: {
      const size_t p = pick(t.size() + 1);
      std::string bytes;
      for (size_t i = 0, n = 1 + pick(8); i < n; ++i) bytes += static_cast<char>(pick(256));
      t.insert(p, bytes);
      break;
    }
    case Damage::Delete: {
      const size_t p = pick(t.size());
      t.erase(p, 1 + pick(16));
      break;
    }
    case Damage::Truncate:
      t.resize(pick(t.size()));
      break;
    case Damage::Digit:
      for (size_t i = 0, n = 1 + pick(3); i < n; ++i) {
        size_t p = pick(t.size());
        for (size_t k = 0; k < t.size() && !(t[p] >= '0' && t[p] <= '9'); ++k) p = (p + 1) % t.size();
        t[p] = static_cast<char>('0' + (t[p] - '0' + 1 + pick(9)) % 10);
      }
      break;
  }
  return t;
}

}  // namespace topopt::testing

"""Deterministic damage to BREP text, the same cases as tests/cpp/hostile/fuzz_brep.h makes
(splitmix64 and the same draws), for the Python half of the hostile-input suite."""

FLIP, INSERT, DELETE, TRUNCATE, DIGIT = range(5)
KINDS = {FLIP: "byte flips", INSERT: "inserts", DELETE: "deletes", TRUNCATE: "truncations", DIGIT: "digit changes"}
_MASK = (1 << 64) - 1


class _Random:
    """splitmix64, as next_random() in fuzz_brep.h."""

    def __init__(self, state):
        self.state = state & _MASK

    def next(self):
        self.state = (self.state + 0x9E3779B97F4A7C15) & _MASK
        z = self.state
        z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & _MASK
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & _MASK
        return z ^ (z >> 31)

    def pick(self, n):
        return self.next() % n


def damage_brep(text, kind, seed):
    """`text` (bytes, not empty) damaged by `kind` with draws from `seed`; returns bytes."""
    r = _Random(seed * 1000003 + kind)
    t = bytearray(text)
    if kind == FLIP:
        for _ in range(1 + r.pick(4)):
            p = r.pick(len(t))
            t[p] ^= 1 + r.pick(255)
    elif kind == INSERT:
        p = r.pick(len(t) + 1)
        n = 1 + r.pick(8)
        t[p:p] = bytes(r.pick(256) for _ in range(n))
    elif kind == DELETE:
        p = r.pick(len(t))
        del t[p:p + 1 + r.pick(16)]
    elif kind == TRUNCATE:
        del t[r.pick(len(t)):]
    elif kind == DIGIT:
        for _ in range(1 + r.pick(3)):
            p = r.pick(len(t))
            for _ in range(len(t)):
                if 48 <= t[p] <= 57:
                    break
                p = (p + 1) % len(t)
            t[p] = 48 + (t[p] - 48 + 1 + r.pick(9)) % 10
    return bytes(t)

// A triangle surface under local edits (see editable_surface.h).
#include "result/editable_surface.h"

#include <algorithm>

namespace topopt::result {

EditableSurface::EditableSurface(const MatX3i& F, const VecXi& tag, long points)
    : tris_(F.rows()), tags_(tag.data(), tag.data() + tag.size()), alive_(F.rows(), 1), star_(points) {
  for (long t = 0; t < F.rows(); ++t) {
    tris_[t] = {F(t, 0), F(t, 1), F(t, 2)};
    for (int k = 0; k < 3; ++k) star_[F(t, k)].push_back(static_cast<int>(t));
  }
}

std::vector<int> EditableSurface::edge_triangles(int a, int b) const {
  std::vector<int> out;
  for (int t : star_[a])
    if (std::count(tris_[t].begin(), tris_[t].end(), b)) out.push_back(t);
  return out;
}

std::vector<int> EditableSurface::neighbours(int a) const {
  std::vector<int> out;
  for (int t : star_[a])
    for (int v : tris_[t])
      if (v != a) out.push_back(v);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

int EditableSurface::third(int t, int a, int b) const {
  for (int v : tris_[t])
    if (v != a && v != b) return v;
  return -1;
}

bool EditableSurface::link_condition(int a, int b) const {
  if (edge_triangles(a, b).size() != 2) return false;
  const std::vector<int> na = neighbours(a), nb = neighbours(b);
  std::vector<int> common;
  std::set_intersection(na.begin(), na.end(), nb.begin(), nb.end(), std::back_inserter(common));
  return common.size() == 2;
}

void EditableSurface::drop(int v, int t) {
  star_[v].erase(std::remove(star_[v].begin(), star_[v].end(), t), star_[v].end());
}

void EditableSurface::collapse(int v, int u) {
  for (int t : edge_triangles(u, v)) {
    alive_[t] = 0;
    for (int w : tris_[t]) drop(w, t);
  }
  for (int t : star_[v]) std::replace(tris_[t].begin(), tris_[t].end(), v, u), star_[u].push_back(t);
  star_[v].clear();
}

bool EditableSurface::flip_of(int a, int b, Flip& f) const {
  const std::vector<int> e = edge_triangles(a, b);
  if (e.size() != 2 || tags_[e[0]] != tags_[e[1]]) return false;
  auto has_ab = [&](int t) {
    for (int k = 0; k < 3; ++k)
      if (tris_[t][k] == a && tris_[t][(k + 1) % 3] == b) return true;
    return false;
  };
  f.t1 = e[0], f.t2 = e[1];
  if (!has_ab(f.t1)) std::swap(f.t1, f.t2);
  if (!has_ab(f.t1) || has_ab(f.t2)) return false;
  f.c = third(f.t1, a, b), f.d = third(f.t2, a, b);
  if (f.c == f.d || !edge_triangles(f.c, f.d).empty()) return false;
  f.u = {a, f.d, f.c}, f.w = {f.d, b, f.c};
  return true;
}

void EditableSurface::flip(int a, int b, const Flip& f) {
  tris_[f.t1] = f.u, tris_[f.t2] = f.w;
  star_[f.d].push_back(f.t1), star_[f.c].push_back(f.t2);
  drop(b, f.t1), drop(a, f.t2);
}

int EditableSurface::split_edge(int a, int b) {
  const int p = points();
  star_.emplace_back();
  for (int t : edge_triangles(a, b)) {
    const Tri old = tris_[t];
    int k = 0;  // old = (x, y, c) with {x, y} = {a, b}, read from the edge's first point
    while (!((old[k] == a || old[k] == b) && (old[(k + 1) % 3] == a || old[(k + 1) % 3] == b))) ++k;
    const int x = old[k], y = old[(k + 1) % 3], c = old[(k + 2) % 3];
    const int n = triangles();
    tris_[t] = {x, p, c};
    tris_.push_back({p, y, c}), tags_.push_back(tags_[t]), alive_.push_back(1);
    drop(y, t);
    star_[y].push_back(n), star_[c].push_back(n), star_[p].push_back(t), star_[p].push_back(n);
  }
  return p;
}

void EditableSurface::live(MatX3i& F, VecXi& tag, const std::vector<int>* new_index) const {
  const long n = std::count(alive_.begin(), alive_.end(), 1);
  F.resize(n, 3);
  tag.resize(n);
  long row = 0;
  for (size_t t = 0; t < tris_.size(); ++t) {
    if (!alive_[t]) continue;
    for (int k = 0; k < 3; ++k) F(row, k) = new_index ? (*new_index)[tris_[t][k]] : tris_[t][k];
    tag[row++] = tags_[t];
  }
}

std::vector<char> EditableSurface::used_points() const {
  std::vector<char> used(star_.size(), 0);
  for (size_t v = 0; v < star_.size(); ++v) used[v] = !star_[v].empty();
  return used;
}

}  // namespace topopt::result

#include "light_tree/light_tree.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cfloat>
#include <cmath>
#include <memory>
#include <stdexcept>

namespace canopy {
namespace {

constexpr float kPi = M_PI_F;
constexpr float kHalfPi = 1.57079637f;                  // float(pi/2) == acosf(0)
constexpr int kMaxBinaryDepth = 2 * LT_MAX_NODE_LEVELS; // leaves at binary depth <= 30
constexpr int kMaxBins = 64;
constexpr int kParallelBinning = 1 << 16;
constexpr int kPackLeaves = 16; // clusters of <= kPackLeaves * leaf_size emitters are packed

inline float3 vmin(float3 a, float3 b) {
  return {b.x < a.x ? b.x : a.x, b.y < a.y ? b.y : a.y, b.z < a.z ? b.z : a.z};
}
inline float3 vmax(float3 a, float3 b) {
  return {a.x < b.x ? b.x : a.x, a.y < b.y ? b.y : a.y, a.z < b.z ? b.z : a.z};
}
inline float comp(float3 v, int axis) {
  return axis == 0 ? v.x : (axis == 1 ? v.y : v.z);
}

// A cone with cached cos/sin of theta_o for the cheap "already covered" test and M_Omega.
struct HCone {
  float3 axis{0, 0, 1};
  float to = 0, te = 0, co = 1, so = 0;
  bool empty = true;
};
inline HCone hcone(const LtCone& c) {
  HCone h;
  h.axis = c.axis;
  h.to = c.theta_o;
  h.te = c.theta_e;
  h.co = c.theta_o >= kPi ? -1.0f : (c.theta_o == 0.0f ? 1.0f : std::cos(c.theta_o));
  h.so = c.theta_o >= kPi || c.theta_o == 0.0f ? 0.0f : std::sin(c.theta_o);
  h.empty = false;
  return h;
}
inline LtCone ltcone(const HCone& h) {
  return lt_make_cone(h.axis, h.to, h.te);
}

// Alg. 1 for a cone `a` not covering the narrower `b` when the union is less than the sphere,
// without trigonometry but one atan2: every angle sum and the half angle theta_r are formed from
// (cos, sin) pairs, all in double. The new axis is a rotated towards b by theta_r, theta_o =
// theta_o(a) + theta_r, padded by LT_CONE_PAD and then checked to cover both inputs. Returns false
// (the caller uses lt_cone_union) for nearly parallel axes or when the check fails.
inline bool hunion_rotate(const HCone& a, const HCone& b, float te, HCone* out) {
  const double ax = a.axis.x, ay = a.axis.y, az = a.axis.z;
  const double bx = b.axis.x, by = b.axis.y, bz = b.axis.z;
  const double cd = ax * bx + ay * by + az * bz;
  const double kx = ay * bz - az * by, ky = az * bx - ax * bz, kz = ax * by - ay * bx;
  const double sd = std::sqrt(kx * kx + ky * ky + kz * kz);
  if (!(sd > 1e-4)) return false;
  const double ca = a.co, sa = a.so, cb = b.co, sb = b.so;
  const double c1 = cd * cb - sd * sb, s1 = sd * cb + cd * sb;     // theta_d + theta_o(b)
  const double cphi = c1 * ca + s1 * sa, sphi = s1 * ca - c1 * sa; // ... - theta_o(a)
  if (!(sphi >= 0.0)) return false;
  double cr, sr; // theta_r = phi / 2 in [0, pi/2]
  if (cphi >= 0.0) {
    cr = std::sqrt((1.0 + cphi) * 0.5);
    sr = sphi / (2.0 * cr);
  } else {
    sr = std::sqrt((1.0 - cphi) * 0.5);
    cr = sphi / (2.0 * sr);
  }
  // unit vector perpendicular to a.axis, towards b.axis
  const double wx = (bx - ax * cd) / sd, wy = (by - ay * cd) / sd, wz = (bz - az * cd) / sd;
  double nx = ax * cr + wx * sr, ny = ay * cr + wy * sr, nz = az * cr + wz * sr;
  const double nl = std::sqrt(nx * nx + ny * ny + nz * nz);
  const float3 axis = make_float3(float(nx / nl), float(ny / nl), float(nz / nl));
  const double co = ca * cr - sa * sr, so = sa * cr + ca * sr; // theta_o(a) + theta_r
  if (!(so > 0.0)) return false;
  const double pad = LT_CONE_PAD;
  const double to = std::atan2(so, co) + pad;
  if (!(to < M_PI)) return false;
  const double cop = co - so * pad, sop = so + co * pad; // cos, sin of `to` (to O(pad^2))
  for (const HCone* x : {&a, &b}) {
    // covered iff alpha = angle(axis, x.axis) <= delta = to - theta_o(x): sin(delta - alpha) > 0
    const double dx = x->axis.x, dy = x->axis.y, dz = x->axis.z;
    const double d = axis.x * dx + axis.y * dy + axis.z * dz;
    const double ex = axis.y * dz - axis.z * dy, ey = axis.z * dx - axis.x * dz,
                 ez = axis.x * dy - axis.y * dx;
    const double e = std::sqrt(ex * ex + ey * ey + ez * ez);
    const double cdel = cop * x->co + sop * x->so, sdel = sop * x->co - cop * x->so;
    if (!(sdel * d - cdel * e > 0.0)) return false;
  }
  HCone r;
  r.axis = axis;
  float tf = static_cast<float>(to);
  if (double(tf) < to) tf = std::nextafter(tf, FLT_INF);
  r.to = tf;
  r.te = te;
  r.co = static_cast<float>(cop);
  r.so = static_cast<float>(sop);
  r.empty = false;
  *out = r;
  return true;
}

// Alg. 1 with fast paths for the common cases (one cone already covers the other).
inline HCone hunion(const HCone& x, const HCone& y) {
  if (y.empty) return x;
  if (x.empty) return y;
  const HCone& a = x.to >= y.to ? x : y;
  const HCone& b = x.to >= y.to ? y : x;
  float te = a.te < b.te ? b.te : a.te;
  if (a.to >= kPi) {
    HCone r = a;
    r.te = te;
    return r;
  }
  float cd = dot(a.axis, b.axis);
  // The union's theta_o, (to_a + theta_d + to_b) / 2, reaches pi iff theta_d >= 2pi - to_a - to_b,
  // i.e. (when to_a + to_b >= pi) iff cos(theta_d) <= cos(to_a + to_b): the whole sphere (what
  // Alg. 1 returns then), without trigonometry. Rounding here only ever widens the cone.
  if (a.to + b.to >= kPi && cd <= a.co * b.co - a.so * b.so) {
    HCone r = a;
    r.to = kPi;
    r.co = -1.0f;
    r.so = 0.0f;
    r.te = te;
    return r;
  }
  // covered iff theta_d <= to_a - to_b, i.e. cos(theta_d) >= cos(to_a - to_b); the margin keeps
  // rounding of the cosines on the safe side.
  if ((a.axis.x == b.axis.x && a.axis.y == b.axis.y && a.axis.z == b.axis.z) ||
      cd >= a.co * b.co + a.so * b.so + 1e-6f) {
    HCone r = a;
    r.te = te;
    return r;
  }
  HCone r;
  if (hunion_rotate(a, b, te, &r)) return r;
  return hcone(lt_cone_union(ltcone(a), ltcone(b)));
}

// M_Omega (Eq. 1) from cached cos/sin; the common theta_e = pi/2 needs no trigonometry:
// to <= pi/2: 2pi - pi cos(to) + pi^2/2 sin(to); to > pi/2: 2pi(1 - cos to) + pi sin(to)(pi - to).
inline float m_omega(const HCone& c) {
  if (c.to >= kPi) return 4.0f * kPi;
  if (c.te == kHalfPi) {
    if (c.to <= kHalfPi) return 2.0f * kPi - kPi * c.co + 0.5f * kPi * kPi * c.so;
    return 2.0f * kPi * (1.0f - c.co) + kPi * c.so * (kPi - c.to);
  }
  return lt_m_omega(c.to, c.te);
}

// Largest ratio of emitter energies that leaf packing may put together (see similar_energies).
constexpr float kPackEnergyRatio = 1024.0f;

struct Prim {
  float3 bmin, bmax, c;
  HCone cone;
  float e;
  int id;
};

struct Acc {
  float3 bmin{FLT_INF, FLT_INF, FLT_INF}, bmax{-FLT_INF, -FLT_INF, -FLT_INF};
  float3 cmin{FLT_INF, FLT_INF, FLT_INF}, cmax{-FLT_INF, -FLT_INF, -FLT_INF};
  HCone cone;
  double e = 0, e2 = 0;
  int count = 0;

  void add(const Prim& p) {
    bmin = vmin(bmin, p.bmin);
    bmax = vmax(bmax, p.bmax);
    cmin = vmin(cmin, p.c);
    cmax = vmax(cmax, p.c);
    cone = hunion(cone, p.cone);
    e += p.e;
    e2 += double(p.e) * double(p.e);
    ++count;
  }
  void merge(const Acc& o) {
    if (o.count == 0) return;
    bmin = vmin(bmin, o.bmin);
    bmax = vmax(bmax, o.bmax);
    cmin = vmin(cmin, o.cmin);
    cmax = vmax(cmax, o.cmax);
    cone = hunion(cone, o.cone);
    e += o.e;
    e2 += o.e2;
    count += o.count;
  }
};

// Surface-area measure M_A with a guard for flat/degenerate boxes: the area plus a small multiple
// (relative to the parent's size) of the edge lengths, so collinear emitters still compare.
inline float area_measure(float3 bmin, float3 bmax, float delta) {
  float3 d = vmax(bmax - bmin, make_float3(0, 0, 0));
  return 2.0f * (d.x * d.y + d.y * d.z + d.z * d.x) + delta * (d.x + d.y + d.z);
}

Acc reduce_range(const Prim* prims, int begin, int end) {
  if (end - begin > kParallelBinning) {
    return tbb::parallel_reduce(
        tbb::blocked_range<int>(begin, end, 1 << 14), Acc(),
        [&](const tbb::blocked_range<int>& r, Acc a) {
          for (int i = r.begin(); i != r.end(); ++i)
            a.add(prims[i]);
          return a;
        },
        [](Acc a, const Acc& b) {
          a.merge(b);
          return a;
        });
  }
  Acc a;
  for (int i = begin; i < end; ++i)
    a.add(prims[i]);
  return a;
}

// Bins of the three axes, nbins each (bins[axis * nbins + i]).
struct BinSet {
  int nbins = 0;
  std::vector<Acc> bins;
  explicit BinSet(int nb = 0) : nbins(nb), bins(3 * size_t(nb)) {}
  Acc& at(int axis, int i) { return bins[size_t(axis) * nbins + i]; }
  const Acc& at(int axis, int i) const { return bins[size_t(axis) * nbins + i]; }
};

struct BinMap {
  float origin[3];
  float scale[3];
  bool active[3];
  int nbins;
  int index(float3 c, int axis) const {
    int k = static_cast<int>((comp(c, axis) - origin[axis]) * scale[axis]);
    return k < 0 ? 0 : (k >= nbins ? nbins - 1 : k);
  }
};

class Builder {
public:
  Builder(std::vector<Prim>& prims, BinaryLightNode* nodes, const LightTreeBuildOptions& opt)
      : prims_(prims), nodes_(nodes), opt_(opt) {}

  std::atomic<int> next{1};
  std::atomic<int> max_depth{0};

  void build(int ni, int begin, int end, int depth, const Acc& acc) {
    BinaryLightNode& node = nodes_[ni];
    const int n = end - begin;
    node.bmin = acc.bmin;
    node.bmax = acc.bmax;
    node.cone = ltcone(acc.cone);
    node.energy = acc.e;
    node.energy2 = acc.e2;
    node.count = n;
    node.first = begin;
    node.left = node.right = -1;

    int d = max_depth.load(std::memory_order_relaxed);
    while (depth > d && !max_depth.compare_exchange_weak(d, depth)) {
    }
    if (n <= 1 || n <= opt_.leaf_size || depth >= kMaxBinaryDepth) {
      if (n > LT_MAX_LEAF) throw std::logic_error("light tree: leaf too large");
      return;
    }
    // Small clusters (at most kPackLeaves leaves' worth, 64 emitters) are packed into as few full
    // leaves as possible: every split puts a multiple of leaf_size emitters on the left, so all
    // leaves but one are full. Fuller leaves and fuller 4-wide nodes keep the tree with its
    // emitter records under 64 bytes/emitter. Among those splits, the SAOH cost (Eq. 2, exact
    // sweeps over the emitters sorted along each axis) chooses, so small clusters are split by
    // orientation too (the paper's Fig. 5 roof of 32 triangles: one slope per child).
    if (n <= kPackLeaves * opt_.leaf_size && similar_energies(begin, end)) {
      Acc l, r;
      int m = pack_split(begin, end, depth, acc, &l, &r);
      recurse(ni, begin, m, end, depth, l, r);
      return;
    }
    // Child capacity at depth + 1 so every leaf ends at binary depth <= kMaxBinaryDepth.
    const long long cap = 1LL << std::min(62, kMaxBinaryDepth + 1 - depth);

    const double weight = acc.e > 0 ? acc.e : double(n);
    int axis = -1, split_bin = -1;
    Acc left_acc, right_acc;
    double best = INFINITY;
    float3 cext = acc.cmax - acc.cmin;
    bool any_extent = cext.x > 0 || cext.y > 0 || cext.z > 0;
    if (any_extent) {
      BinMap map;
      map.nbins = std::max(2, std::min({opt_.bins, kMaxBins, n}));
      for (int a = 0; a < 3; ++a) {
        float ext = comp(cext, a);
        map.active[a] = ext > 0 && std::isfinite(ext);
        map.origin[a] = comp(acc.cmin, a);
        map.scale[a] = map.active[a] ? float(map.nbins) * (1.0f - 1e-6f) / ext : 0.0f;
      }
      BinSet bs = bin(begin, end, map);
      float3 ext = acc.bmax - acc.bmin;
      float lmax = std::max({ext.x, ext.y, ext.z});
      float delta = 1e-3f * lmax;
      double parent_measure = double(area_measure(acc.bmin, acc.bmax, delta)) * m_omega(acc.cone);
      if (!(parent_measure > 0)) parent_measure = 1;
      std::vector<Acc> prefix(map.nbins);
      for (int a = 0; a < 3; ++a) {
        float len = comp(ext, a);
        if (!map.active[a] || !(len > 0)) continue; // zero-length axis: skip
        double kr = double(lmax) / double(len);
        prefix[0] = bs.at(a, 0);
        for (int i = 1; i < map.nbins; ++i) {
          prefix[i] = prefix[i - 1];
          prefix[i].merge(bs.at(a, i));
        }
        Acc suffix;
        for (int i = map.nbins - 1; i >= 1; --i) {
          suffix.merge(bs.at(a, i));
          const Acc& l = prefix[i - 1];
          if (l.count == 0 || suffix.count == 0) continue;
          double wl = acc.e > 0 ? l.e : double(l.count);
          double wr = acc.e > 0 ? suffix.e : double(suffix.count);
          double cost =
              kr *
              (wl * area_measure(l.bmin, l.bmax, delta) * m_omega(l.cone) +
               wr * area_measure(suffix.bmin, suffix.bmax, delta) * m_omega(suffix.cone)) /
              parent_measure;
          if (cost < best) {
            best = cost;
            axis = a;
            split_bin = i - 1;
            left_acc = l;
            right_acc = suffix;
          }
        }
      }
      if (n <= LT_MAX_LEAF && (axis < 0 || best >= weight)) return; // leaf cost E_c wins
      if (axis >= 0 && (left_acc.count > cap || right_acc.count > cap)) axis = -1;
      if (axis >= 0) {
        Prim* mid = std::partition(prims_.data() + begin, prims_.data() + end, [&](const Prim& p) {
          return map.index(p.c, axis) <= split_bin;
        });
        int m = static_cast<int>(mid - prims_.data());
        if (m - begin != left_acc.count) throw std::logic_error("light tree: partition mismatch");
        recurse(ni, begin, m, end, depth, left_acc, right_acc);
        return;
      }
    } else if (n <= LT_MAX_LEAF) {
      return; // coincident emitters: one leaf
    }
    // Fallback: median split (by index when all centroids coincide, else on the widest axis).
    int m = begin + n / 2;
    if (any_extent) {
      int a = cext.x >= cext.y && cext.x >= cext.z ? 0 : (cext.y >= cext.z ? 1 : 2);
      std::nth_element(prims_.data() + begin, prims_.data() + m, prims_.data() + end,
                       [a](const Prim& p, const Prim& q) { return comp(p.c, a) < comp(q.c, a); });
    }
    Acc l, r;
    if (n > kParallelBinning) {
      tbb::parallel_invoke([&] { l = reduce_range(prims_.data(), begin, m); },
                           [&] { r = reduce_range(prims_.data(), m, end); });
    } else {
      l = reduce_range(prims_.data(), begin, m);
      r = reduce_range(prims_.data(), m, end);
    }
    recurse(ni, begin, m, end, depth, l, r);
  }

private:
  // The packing split of a cluster of at most kPackLeaves * leaf_size emitters (see build): the
  // left child gets leaf_size * j emitters. Where the emitters' cones differ, j and the axis are
  // chosen by the least SAOH cost among the j whose children still fit the bit-trail depth
  // (ceil(log2(leaves)) more levels each); the sweeps accumulate whole leaves' worth of emitters
  // (chunks), then merge chunks. Where every cone is the same (or every one is the full sphere,
  // e.g. point lights), M_Omega is the same for every child and the split is the balanced median
  // along the widest centroid axis, as fast as before. Reorders prims_[begin, end), returns the
  // split index and the children's accumulators.
  int pack_split(int begin, int end, int depth, const Acc& acc, Acc* lo, Acc* hi) {
    const int n = end - begin, ls = opt_.leaf_size;
    const int leaves = (n + ls - 1) / ls;
    int m = begin + ls * ((leaves + 1) / 2);
    const float3 cext = acc.cmax - acc.cmin;
    Prim* p = prims_.data() + begin;
    auto sort_axis = [&](int a) {
      std::sort(p, p + n, [a](const Prim& x, const Prim& y) {
        float cx = comp(x.c, a), cy = comp(y.c, a);
        return cx < cy || (cx == cy && x.id < y.id);
      });
    };
    auto median = [&] {
      if (cext.x > 0 || cext.y > 0 || cext.z > 0) {
        int a = cext.x >= cext.y && cext.x >= cext.z ? 0 : (cext.y >= cext.z ? 1 : 2);
        std::nth_element(p, prims_.data() + m, p + n,
                         [a](const Prim& x, const Prim& y) { return comp(x.c, a) < comp(y.c, a); });
      }
      *lo = reduce_range(prims_.data(), begin, m);
      *hi = reduce_range(prims_.data(), m, end);
      return m;
    };
    bool all_full = true, all_same = true;
    const HCone& c0 = p[0].cone;
    for (int i = 0; i < n; ++i) {
      const HCone& c = p[i].cone;
      all_full = all_full && c.to >= kPi;
      all_same = all_same && c.to == c0.to && c.te == c0.te && c.axis.x == c0.axis.x &&
                 c.axis.y == c0.axis.y && c.axis.z == c0.axis.z;
    }
    if (all_full || all_same || !(cext.x > 0 || cext.y > 0 || cext.z > 0)) return median();

    const int room = kMaxBinaryDepth - depth - 1; // levels below each child
    auto fits = [&](int count) {
      int lv = (count + ls - 1) / ls, need = 0;
      while ((1 << need) < lv)
        ++need;
      return need <= room;
    };
    const float3 ext = acc.bmax - acc.bmin;
    const float lmax = std::max({ext.x, ext.y, ext.z});
    const float delta = 1e-3f * lmax;
    std::array<Acc, kPackLeaves + 1> left, right; // the first / last chunks up to chunk j
    double best = INFINITY;
    int best_axis = -1, best_j = 0, sorted = -1;
    for (int a = 0; a < 3; ++a) {
      const float len = comp(ext, a);
      if (!(comp(cext, a) > 0) || !(len > 0)) continue;
      sort_axis(a);
      sorted = a;
      for (int j = 0; j < leaves; ++j) { // right[j]: chunk j alone for now
        right[j] = Acc();
        for (int i = ls * j; i < std::min(n, ls * (j + 1)); ++i)
          right[j].add(p[i]);
      }
      left[0] = Acc();
      for (int j = 1; j < leaves; ++j) {
        left[j] = left[j - 1];
        left[j].merge(right[j - 1]);
      }
      for (int j = leaves - 2; j >= 1; --j)
        right[j].merge(right[j + 1]); // right[j]: chunks j .. leaves - 1
      const double kr = double(lmax) / double(len);
      for (int j = 1; j < leaves; ++j) {
        const Acc &l = left[j], &r = right[j];
        if (!fits(l.count) || !fits(r.count)) continue;
        const double wl = acc.e > 0 ? l.e : double(l.count);
        const double wr = acc.e > 0 ? r.e : double(r.count);
        const double cost = kr * (wl * area_measure(l.bmin, l.bmax, delta) * m_omega(l.cone) +
                                  wr * area_measure(r.bmin, r.bmax, delta) * m_omega(r.cone));
        if (cost < best) {
          best = cost;
          best_axis = a;
          best_j = j;
          *lo = l;
          *hi = r;
        }
      }
    }
    if (best_axis < 0) return median(); // no split fits the depth: the balanced median
    if (sorted != best_axis) sort_axis(best_axis);
    return begin + ls * best_j;
  }

  void recurse(int ni, int begin, int mid, int end, int depth, const Acc& l, const Acc& r) {
    int li = next.fetch_add(2);
    nodes_[ni].left = li;
    nodes_[ni].right = li + 1;
    if (end - begin > opt_.parallel_grain) {
      tbb::parallel_invoke([&] { build(li, begin, mid, depth + 1, l); },
                           [&] { build(li + 1, mid, end, depth + 1, r); });
    } else {
      build(li, begin, mid, depth + 1, l);
      build(li + 1, mid, end, depth + 1, r);
    }
  }

  void bin_serial(const Prim* p, int begin, int end, const BinMap& map, BinSet& bs) const {
    for (int a = 0; a < 3; ++a) {
      if (!map.active[a]) continue;
      for (int i = begin; i < end; ++i)
        bs.at(a, map.index(p[i].c, a)).add(p[i]);
    }
  }

  BinSet bin(int begin, int end, const BinMap& map) const {
    const Prim* p = prims_.data();
    if (end - begin > kParallelBinning) {
      return tbb::parallel_reduce(
          tbb::blocked_range<int>(begin, end, 1 << 14), BinSet(map.nbins),
          [&](const tbb::blocked_range<int>& r, BinSet bs) {
            bin_serial(p, r.begin(), r.end(), map, bs);
            return bs;
          },
          [&](BinSet a, const BinSet& b) {
            for (int ax = 0; ax < 3; ++ax)
              for (int i = 0; i < map.nbins; ++i)
                a.at(ax, i).merge(b.at(ax, i));
            return a;
          });
    }
    BinSet bs(map.nbins);
    bin_serial(p, begin, end, map, bs);
    return bs;
  }

  std::vector<Prim>& prims_;
  // Packing ignores energy: it would put a bright emitter in one leaf with dim ones beside it, and
  // the leaf's importance (its summed energy, its union cone) then hides them wherever the bright
  // one does not reach (a 1e12 spot beside 1e-12 lights: their pmf is 1e-24 where only they
  // shine). Clusters whose positive energies span more than kPackEnergyRatio go through SAOH,
  // whose cost (energy x orientation x area) separates them.
  bool similar_energies(int begin, int end) const {
    float lo = FLT_MAX, hi = 0.0f;
    for (int i = begin; i < end; ++i) {
      float e = prims_[size_t(i)].e;
      if (!(e > 0.0f)) continue;
      lo = std::min(lo, e);
      hi = std::max(hi, e);
    }
    return !(hi > kPackEnergyRatio * lo);
  }

  BinaryLightNode* nodes_; // room for 2n - 1 nodes, written in place (see the caller)
  const LightTreeBuildOptions& opt_;
};

} // namespace

float BinaryLightNode::cv2() const {
  if (!(energy > 0) || count <= 1) return 0.0f;
  double v = double(count) * energy2 / (energy * energy) - 1.0;
  return v > 0 ? static_cast<float>(v) : 0.0f;
}

namespace {
// EmitterBounds::plane_h. The renderer's emission test is dot(L.n, P - x) > 0 for the sampled or
// hit point x (cl/lights/light_sample.h), so the emitter sends nothing to P if dot(n, P) <= min
// over its vertices of dot(n, x) (a linear function is smallest at a vertex of the polygon). The
// margin, 2^-20 (|p| + |e1| + |e2|) in the 1-norm, covers the rounding of the sample points
// (gamma(6) of the same sum, cl/lights/light_sample.h), of the geometry triangles' vertices, of n's
// normalisation (L.n's direction to ~1e-7 times the emitter's radius) and of this double
// evaluation. A one-sided disk emits towards P iff dot(n, P - centre) > 0 (cl/lights/light_sample.h
// tests the centre, whatever the sampled or hit point), so h is dot(n, c - centre) plus the same
// margin, with |centre| + 2r per axis in place of |p| + |e1| + |e2|.
double disk_plane_offset(const Light& l, const EmitterBounds& b) {
  const float3 n = b.cone.axis;
  const float4 c = lt_sphere_of_box(b.bmin, b.bmax);
  const double cc[3] = {c.x, c.y, c.z}, p[3] = {l.p.x, l.p.y, l.p.z}, nn[3] = {n.x, n.y, n.z};
  const double r = std::fabs(double(l.p.w));
  double h = 0, norm1 = 0;
  for (int k = 0; k < 3; ++k) {
    h += nn[k] * (cc[k] - p[k]);
    norm1 += std::fabs(p[k]) + 2.0 * r;
  }
  h += std::ldexp(norm1, -20);
  return std::isfinite(h) ? h : NAN;
}

double plane_offset(const Light& l, const EmitterBounds& b) {
  if (l.type == LIGHT_DISK && !(l.flags & LIGHT_FLAG_TWO_SIDED) && b.cos_o >= 1.0f) {
    const double nl =
        std::sqrt(double(l.n.x) * l.n.x + double(l.n.y) * l.n.y + double(l.n.z) * l.n.z);
    if (!(nl > 0) || !std::isfinite(nl)) return NAN;
    return disk_plane_offset(l, b);
  }
  if ((l.type != LIGHT_QUAD && l.type != LIGHT_TRIANGLE) || (l.flags & LIGHT_FLAG_TWO_SIDED) ||
      b.cos_o < 1.0f)
    return NAN;
  const double nl =
      std::sqrt(double(l.n.x) * l.n.x + double(l.n.y) * l.n.y + double(l.n.z) * l.n.z);
  if (!(nl > 0) || !std::isfinite(nl)) return NAN; // no emitting side
  const float3 n = b.cone.axis;
  const float4 c = lt_sphere_of_box(b.bmin, b.bmax);
  const double p[3] = {l.p.x, l.p.y, l.p.z}, e1[3] = {l.e1.x, l.e1.y, l.e1.z},
               e2[3] = {l.e2.x, l.e2.y, l.e2.z}, cc[3] = {c.x, c.y, c.z}, nn[3] = {n.x, n.y, n.z};
  double h = -INFINITY, norm1 = 0;
  const int corners = l.type == LIGHT_QUAD ? 4 : 3;
  for (int v = 0; v < corners; ++v) {
    double s = 0;
    for (int k = 0; k < 3; ++k) {
      double x = p[k] + ((v & 1) ? e1[k] : 0.0) + ((v & 2) ? e2[k] : 0.0);
      s += nn[k] * (cc[k] - x);
    }
    h = std::max(h, s);
  }
  for (int k = 0; k < 3; ++k)
    norm1 += std::fabs(p[k]) + std::fabs(e1[k]) + std::fabs(e2[k]);
  h += std::ldexp(norm1, -20);
  return std::isfinite(h) ? h : NAN;
}
} // namespace

EmitterBounds emitter_bounds(const Light& light) {
  EmitterBounds b;
  float3 axis;
  float co, ce, e_float; // lt_light_bounds' float energy underflows for emission ~1e-40: unused
  lt_light_bounds(&light, &b.bmin, &b.bmax, &axis, &co, &ce, &e_float);
  b.cos_o = co;
  b.cos_e = ce;
  float to = co >= 1.0f ? 0.0f : (co <= -1.0f ? kPi : std::acos(co));
  float te = ce <= 0.0f ? kHalfPi : std::acos(ce);
  b.cone = lt_make_cone(axis, to, te);
  // lt_light_bounds' energy again in double: luminance times area (sphere: pi r^2)
  double lum = 0.2126 * double(light.emission.x) + 0.7152 * double(light.emission.y) +
               0.0722 * double(light.emission.z);
  double energy = lum;
  if (light.type == LIGHT_SPHERE) {
    energy = lum * M_PI * double(light.p.w) * double(light.p.w);
  } else if (light.type == LIGHT_QUAD || light.type == LIGHT_TRIANGLE) {
    double e1[3] = {light.e1.x, light.e1.y, light.e1.z},
           e2[3] = {light.e2.x, light.e2.y, light.e2.z};
    double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2],
           cz = e1[0] * e2[1] - e1[1] * e2[0];
    double area = std::sqrt(cx * cx + cy * cy + cz * cz);
    energy = lum * (light.type == LIGHT_QUAD ? area : 0.5 * area);
  } else if (light.type == LIGHT_DISK) {
    energy = lum * M_PI * double(light.p.w) * double(light.p.w);
  }
  b.energy = (energy > 0 && std::isfinite(energy)) ? energy : 0.0;
  b.plane_h = plane_offset(light, b);
  return b;
}

double normalize_emitter_energies(std::vector<EmitterBounds>& emitters) {
  double emax = 0;
  for (const EmitterBounds& b : emitters)
    emax = std::max(emax, b.energy);
  if (!(emax > 0)) return 1.0;
  double scale = std::ldexp(1.0, -std::ilogb(emax)); // emax * scale in [1, 2)
  for (EmitterBounds& b : emitters)
    if (b.energy > 0) b.energy = std::max(b.energy * scale, double(FLT_MIN));
  return scale;
}

std::vector<EmitterBounds> emitter_bounds(const std::vector<Light>& lights) {
  std::vector<EmitterBounds> out(lights.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, lights.size(), 4096),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i)
                        out[i] = emitter_bounds(lights[i]);
                    });
  return out;
}

double saoh_cost(const BinaryLightNode& parent, const BinaryLightNode& left,
                 const BinaryLightNode& right) {
  float3 ext = parent.bmax - parent.bmin;
  float delta = 1e-3f * std::max({ext.x, ext.y, ext.z});
  auto measure = [&](const BinaryLightNode& n) {
    return double(area_measure(n.bmin, n.bmax, delta)) * m_omega(hcone(n.cone));
  };
  return (left.energy * measure(left) + right.energy * measure(right)) / measure(parent);
}

BinaryLightTree build_binary_light_tree(const std::vector<EmitterBounds>& emitters,
                                        const LightTreeBuildOptions& opt_in) {
  LightTreeBuildOptions opt = opt_in;
  opt.bins = std::clamp(opt.bins, 2, kMaxBins);
  opt.leaf_size = std::clamp(opt.leaf_size, 1, LT_MAX_LEAF);
  opt.parallel_grain = std::max(opt.parallel_grain, 64);
  BinaryLightTree bt;
  const int n = static_cast<int>(emitters.size());
  if (n == 0) return bt;
  if (static_cast<long long>(n) >= (1LL << 28))
    throw std::invalid_argument("light tree: too many lights");

  std::vector<Prim> prims(n);
  tbb::parallel_for(tbb::blocked_range<int>(0, n, 4096), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i != r.end(); ++i) {
      const EmitterBounds& e = emitters[i];
      Prim& p = prims[i];
      p.bmin = e.bmin;
      p.bmax = e.bmax;
      p.c = (e.bmin + e.bmax) * 0.5f;
      p.cone = hcone(e.cone);
      p.e = float(e.energy);
      p.id = i;
    }
  });
  // Room for the 2n - 1 nodes of the worst case, allocated without being touched (a build uses
  // far fewer: value-initialising 2n nodes up front cost more page faults than the whole SAOH
  // build of the used ones). BinaryLightNode is an implicit-lifetime type: the builder assigns
  // every field of the nodes it creates.
  std::unique_ptr<BinaryLightNode, void (*)(BinaryLightNode*)> room(
      static_cast<BinaryLightNode*>(
          ::operator new(2 * static_cast<size_t>(n) * sizeof(BinaryLightNode))),
      [](BinaryLightNode* p) { ::operator delete(p); });
  Builder b(prims, room.get(), opt);
  Acc root = reduce_range(prims.data(), 0, n);
  b.build(0, 0, n, 0, root);
  bt.nodes.assign(room.get(), room.get() + b.next.load());
  bt.depth = b.max_depth.load();
  bt.order.resize(n);
  for (int i = 0; i < n; ++i)
    bt.order[i] = prims[i].id;
  return bt;
}

size_t LightTree::device_bytes() const {
  return nodes.size() * sizeof(float4) + children.size() * sizeof(int4) +
         leaf_lights.size() * sizeof(int) + trails.size() * sizeof(uint32_t) + 2 * sizeof(float4);
}

LtTree LightTree::view(const Light* lights) const {
  LtTree t;
  t.nodes = nodes.data();
  t.children = children.data();
  t.leaf_lights = leaf_lights.data();
  t.trails = trails.data();
  t.lights = lights;
  t.root_sphere = root_sphere;
  t.root_info = root_info;
  return t;
}

namespace {
inline float4 splat4(float s) {
  return make_float4(s, s, s, s);
}
inline void set_lane_value(float4& v, int lane, float x) {
  (lane == 0 ? v.x : lane == 1 ? v.y : lane == 2 ? v.z : v.w) = x;
}

// Octahedral encoding of a unit axis in 2 x 16 bits (decoded by lt_oct_decode4, nearest grid
// point); returns the bits and an upper bound of the angle between the decoded and the exact axis.
uint32_t oct_encode(float3 a, double* err) {
  float s = std::fabs(a.x) + std::fabs(a.y) + std::fabs(a.z);
  float px = s > 0 ? a.x / s : 0.0f, py = s > 0 ? a.y / s : 0.0f;
  if (a.z < 0) {
    float fx = (1.0f - std::fabs(py)) * (px >= 0 ? 1.0f : -1.0f);
    float fy = (1.0f - std::fabs(px)) * (py >= 0 ? 1.0f : -1.0f);
    px = fx;
    py = fy;
  }
  double cu = std::clamp(std::nearbyint((double(px) + 1.0) * 0.5 * 65535.0), 0.0, 65535.0);
  double cv = std::clamp(std::nearbyint((double(py) + 1.0) * 0.5 * 65535.0), 0.0, 65535.0);
  float4 ax, ay, az;
  lt_oct_decode4(splat4(float(cu)), splat4(float(cv)), &ax, &ay, &az);
  // angle from the chord between the two (unit up to rounding) vectors, plus that rounding
  double dx = double(ax.x) - a.x, dy = double(ay.x) - a.y, dz = double(az.x) - a.z;
  double chord = std::sqrt(dx * dx + dy * dy + dz * dz);
  *err = 2.0 * std::asin(std::min(1.0, 0.5 * chord)) + 4e-7;
  return uint32_t(cu) | (uint32_t(cv) << 16);
}

// Largest float <= x.
inline float float_down(double x) {
  float f = static_cast<float>(x);
  return double(f) > x ? std::nextafter(f, -FLT_INF) : f;
}

// The unit vector that octahedral bits decode to on the device (lt_oct_decode_v).
float3 oct_decode(uint32_t bits) {
  float4 ax, ay, az;
  lt_oct_decode4(splat4(float(bits & 0xffffu)), splat4(float(bits >> 16)), &ax, &ay, &az);
  return make_float3(ax.x, ay.x, az.x);
}
double chord(float3 a, float3 b) {
  double dx = double(a.x) - b.x, dy = double(a.y) - b.y, dz = double(a.z) - b.z;
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}
// The angle a chord subtends (>= the chord), slightly rounded up.
double chord_angle(double c) {
  return 2.0 * std::asin(std::min(1.0, 0.5 * c)) * (1.0 + 1e-12) + 1e-15;
}
// Largest angle between a lane's decoded axis and an emitter normal for which the lane may keep a
// half-space bound (LT_PLANE_SLOPE covers it plus the test's rounding, LT_PLANE_ROUND).
constexpr double kPlaneAngle = double(LT_PLANE_SLOPE) - double(LT_PLANE_ROUND);

// The emitter record of one emitter (LT_EMITTER_F4 float4, see cl/light_tree/layout.h): sphere;
// (octahedral axis bits, q, energy, light index). q packs the cone: q <= 1: cos(theta_o) with
// theta_e = pi/2; q > 1.5: theta_o = 0 and cos(theta_e) = q - 2 (exact); q < -1.5: a one-sided
// planar emitter, theta_o = LT_PLANE_SLOPE, theta_e = pi/2 and the half-space bound h = (-2 - q) r
// (as the device computes it, >= plane_h; see LT_PLANE_SLOPE).
// The cone is widened by the axis quantisation error (theta_o when theta_e = pi/2, else theta_e),
// so the record's importance is 0 only where the exact emitter's is.
void emitter_record(const EmitterBounds& b, int light, float4* rec) {
  rec[0] = lt_sphere_of_box(b.bmin, b.bmax);
  double err = 0;
  uint32_t oct = oct_encode(b.cone.axis, &err);
  double pad = err * 1.001 + 1e-7;
  double to = b.cos_o >= 1.0f ? 0.0 : (b.cos_o <= -1.0f ? M_PI : std::acos(double(b.cos_o)));
  double te = b.cos_e <= 0.0f ? M_PI / 2 : std::acos(double(b.cos_e));
  const float r = rec[0].w;
  float q;
  if (!std::isnan(b.plane_h) && r > 0.0f && pad <= kPlaneAngle) {
    // dot(n, P - x) = dot(n, P - c) + dot(n, c - x) <= dot(a, P - c) + |n - a| |P - c| + plane_h,
    // and |n - a| <= pad <= kPlaneAngle: the middle term is within LT_PLANE_SLOPE |P - c|.
    // q < -1.5 flags the bound: h > -r / 2 (h >= -r always; a larger h only culls less)
    const double h = std::max(b.plane_h, -0.49 * double(r));
    q = float_down(-2.0 - h / double(r));
    while (std::isfinite(q) && double((-2.0f - q) * r) < h)
      q = std::nextafter(q, -FLT_INF);
    if (!std::isfinite(q)) q = std::max(float_down(std::cos(to + pad)), -1.0f); // no bound
  } else if (b.cos_o <= -1.0f) {
    q = -1.0f; // omnidirectional: the axis does not matter
  } else if (b.cos_e <= 0.0f || to > 0.0) {
    // theta_e = pi/2 (or a general cone, widened to theta_o + theta_e, theta_e = pi/2)
    double t = b.cos_e <= 0.0f ? to + pad : to + te + pad;
    q = t >= M_PI ? -1.0f : std::max(float_down(std::cos(t)), -1.0f);
  } else {
    double t = te + pad; // theta_o = 0
    q = t >= M_PI / 2 ? 1.0f : float_down(2.0 + std::max(std::cos(t), 0.0));
  }
  rec[1] = make_float4(uint_as_float_(oct), q, float(b.energy), uint_as_float_(uint32_t(light)));
}

// Greedy collapse fills every node with four lanes when it can (fewer levels); pairwise collapse
// (each level = two binary levels) is the fallback that always fits the bit-trail budget, since the
// builder keeps leaves at binary depth <= 2 * LT_MAX_NODE_LEVELS. Every binary subtree of at most
// LT_MAX_LEAF emitters becomes one leaf (its emitters are ranked individually by their records).
// The children of a node get consecutive indices (one sibling block, visited depth-first), so the
// prefetch of a node's children touches one contiguous range.
struct TooDeep {};
struct Collapser {
  const BinaryLightTree& bt;
  const std::vector<EmitterBounds>& eb;
  LightTree& t;
  bool greedy;

  // Half-space bound of a lane (see LT_PLANE_SLOPE) whose emitters are all one-sided planar with
  // normals n_i within kPlaneAngle of the decoded axis a: for x on emitter i (sphere c_i, r_i),
  //   dot(n_i, P - x) <= dot(a, P - x) + |n_i - a| |P - x|, |P - x| <= |P - c| + r,
  //   dot(a, P - x) = dot(a, P - c) + dot(a, c - c_i) + dot(a, c_i - x),
  //   dot(a, c_i - x) <= dot(n_i, c_i - x) + |a - n_i| r_i <= plane_h_i + |a - n_i| r_i,
  // so h = max_i [dot(a, c - c_i) + plane_h_i + |n_i - a| (r_i + r)] and |n_i - a| |P - c| is
  // within LT_PLANE_SLOPE |P - c|. Returns the 16-bit k with (k - 32768) * (r * LT_PLANE_H_UNIT)
  // >= h (as the device computes it), or -1 if the lane gets no bound.
  int plane_code(const BinaryLightNode& s, float4 sp, uint32_t oct) const {
    if (!(sp.w > 0.0f) || !(s.cone.theta_o <= 2.0 * kPlaneAngle)) return -1;
    const float3 a = oct_decode(oct);
    const double ax = a.x, ay = a.y, az = a.z;
    double h = -INFINITY, scale = std::fabs(sp.x) + std::fabs(sp.y) + std::fabs(sp.z);
    for (int i = s.first; i < s.first + s.count; ++i) {
      const EmitterBounds& e = eb[size_t(bt.order[size_t(i)])];
      if (std::isnan(e.plane_h)) return -1;
      const double ch = chord(a, e.cone.axis);
      if (chord_angle(ch) > kPlaneAngle) return -1;
      const float4 ci = lt_sphere_of_box(e.bmin, e.bmax);
      const double v = ax * (double(sp.x) - ci.x) + ay * (double(sp.y) - ci.y) +
                       az * (double(sp.z) - ci.z) + e.plane_h + ch * (double(ci.w) + sp.w);
      h = std::max(h, v);
      scale = std::max(scale, double(std::fabs(ci.x) + std::fabs(ci.y) + std::fabs(ci.z)));
    }
    h += std::ldexp(scale, -40); // the double rounding of the dot products
    // signed: h = (k - 32768) * (r * 2^-14), in [-2r, 2r) (|h| <= r up to the margins)
    const float unit = sp.w * LT_PLANE_H_UNIT;
    double k = std::ceil(std::max(h / double(unit), -32768.0)) + 32768.0;
    if (!(k <= 65535.0)) return -1;
    while (k <= 65535.0 && double((float(k) - 32768.0f) * unit) < h)
      k += 1.0;
    return k <= 65535.0 ? int(k) : -1;
  }

  bool leafish(int bi) const {
    const BinaryLightNode& n = bt.nodes[bi];
    return n.is_leaf() || n.count <= LT_MAX_LEAF;
  }

  void set_lane(int node, int lane, const BinaryLightNode& s) {
    float4* f = t.nodes.data() + size_t(node) * LT_NODE_F4;
    float4 sp = lt_sphere_of_box(s.bmin, s.bmax);
    float v[LT_NODE_F4];
    v[LT_CX] = sp.x;
    v[LT_CY] = sp.y;
    v[LT_CZ] = sp.z;
    v[LT_R] = sp.w;
    double err = 0;
    v[LT_AXIS] = uint_as_float_(oct_encode(s.cone.axis, &err));
    // theta_o widened by the axis quantisation error, cosine rounded down
    double to = double(s.cone.theta_o) + err * 1.001 + 1e-7;
    v[LT_COS_O] =
        s.cone.theta_o >= kPi || to >= M_PI ? -1.0f : std::max(float_down(std::cos(to)), -1.0f);
    v[LT_ENERGY] = static_cast<float>(s.energy);
    // cos(theta_e) in 16 bits, rounded down; the energy CV^2 as the high half of a float
    double ce = s.cone.theta_e >= kHalfPi ? 0.0 : std::cos(double(s.cone.theta_e));
    uint32_t k = uint32_t(std::clamp(std::floor(ce * 65535.0), 0.0, 65535.0));
    while (k > 0 && double(float(k) * LT_U16_SCALE) > ce)
      --k;
    uint32_t cv2_bits = float_as_uint_(s.cv2()) & 0xffff0000u;
    int plane = plane_code(s, sp, float_as_uint_(v[LT_AXIS]));
    if (plane >= 0) { // theta_e = pi/2: the 16 bits hold the plane offset
      v[LT_COS_O] = LT_PLANE_FLAG;
      k = uint32_t(plane);
    }
    v[LT_CE_CV2] = uint_as_float_(cv2_bits | k);
    for (int kk = 0; kk < LT_NODE_F4; ++kk)
      set_lane_value(f[kk], lane, v[kk]);
  }

  int alloc_node() {
    int node = t.num_nodes();
    t.children.push_back(make_int4(LT_EMPTY, LT_EMPTY, LT_EMPTY, LT_EMPTY));
    for (int k = 0; k < LT_NODE_F4; ++k)
      t.nodes.push_back(make_float4(0, 0, 0, 0));
    t.nodes[size_t(node) * LT_NODE_F4 + LT_COS_O] = make_float4(1, 1, 1, 1);
    return node;
  }

  void fill(int node, int bi, int level, uint32_t prefix) {
    if (level >= LT_MAX_NODE_LEVELS) {
      if (greedy) throw TooDeep{};
      throw std::logic_error("light tree: too deep for bit-trails");
    }
    t.levels = std::max(t.levels, level + 1);
    int slots[4];
    int ns = 0;
    const BinaryLightNode& x = bt.nodes[bi];
    if (leafish(bi)) {
      slots[ns++] = bi; // the root is a leaf
    } else if (greedy) {
      // Fill the four lanes by repeatedly opening the internal slot with the most emitters.
      slots[ns++] = x.left;
      slots[ns++] = x.right;
      while (ns < 4) {
        int best = -1;
        for (int k = 0; k < ns; ++k)
          if (!leafish(slots[k]) &&
              (best < 0 || bt.nodes[slots[k]].count > bt.nodes[slots[best]].count))
            best = k;
        if (best < 0) break;
        const BinaryLightNode& open = bt.nodes[slots[best]];
        for (int k = ns; k > best + 1; --k)
          slots[k] = slots[k - 1];
        slots[best] = open.left;
        slots[best + 1] = open.right;
        ++ns;
      }
    } else {
      for (int c : {x.left, x.right}) {
        const BinaryLightNode& cn = bt.nodes[c];
        if (leafish(c)) {
          slots[ns++] = c;
        } else {
          slots[ns++] = cn.left;
          slots[ns++] = cn.right;
        }
      }
    }
    int codes[4];
    for (int lane = 0; lane < ns; ++lane)
      codes[lane] = leafish(slots[lane]) ? 0 : alloc_node(); // one contiguous sibling block
    for (int lane = 0; lane < ns; ++lane) {
      const BinaryLightNode& s = bt.nodes[slots[lane]];
      set_lane(node, lane, s);
      uint32_t trail = prefix | (uint32_t(lane) << (2 * level));
      if (leafish(slots[lane])) {
        codes[lane] = lt_leaf_code(s.first, s.count);
        for (int j = 0; j < s.count; ++j)
          t.trails[bt.order[s.first + j]] = trail | (uint32_t(j) << (2 * (level + 1)));
      }
      int4& ch = t.children[node];
      (lane == 0 ? ch.x : lane == 1 ? ch.y : lane == 2 ? ch.z : ch.w) = codes[lane];
    }
    for (int lane = 0; lane < ns; ++lane)
      if (!leafish(slots[lane]))
        fill(codes[lane], slots[lane], level + 1, prefix | (uint32_t(lane) << (2 * level)));
  }
};
} // namespace

LightTree collapse_light_tree(const BinaryLightTree& bt, const std::vector<EmitterBounds>& eb) {
  LightTree t;
  const int num_lights = static_cast<int>(eb.size());
  t.num_lights = num_lights;
  if (bt.nodes.empty()) return t;
  for (bool greedy : {true, false}) {
    t.trails.assign(num_lights, 0u);
    t.leaf_lights = bt.order;
    t.nodes.clear();
    t.children.clear();
    t.levels = 0;
    t.nodes.reserve(bt.nodes.size() / 6 * LT_NODE_F4 + LT_NODE_F4 +
                    size_t(num_lights) * LT_EMITTER_F4);
    t.children.reserve(bt.nodes.size() / 6 + 1);
    Collapser c{bt, eb, t, greedy};
    try {
      c.fill(c.alloc_node(), 0, 0, 0u);
      break;
    } catch (const TooDeep&) {
    }
  }
  // Emitter records in leaf order after the node records.
  const size_t base = t.nodes.size();
  t.nodes.resize(base + size_t(num_lights) * LT_EMITTER_F4);
  float4* rec = t.nodes.data() + base;
  tbb::parallel_for(
      tbb::blocked_range<int>(0, num_lights, 4096), [&](const tbb::blocked_range<int>& r) {
        for (int i = r.begin(); i != r.end(); ++i)
          emitter_record(eb[bt.order[i]], bt.order[i], rec + size_t(i) * LT_EMITTER_F4);
      });
  const BinaryLightNode& root = bt.nodes[0];
  t.root_sphere = lt_sphere_of_box(root.bmin, root.bmax);
  t.root_info = make_float4(root.cv2(), static_cast<float>(root.energy),
                            uint_as_float_(uint32_t(base) + LT_EMITTER_BASE_BIAS), 0);
  return t;
}

LightTree build_light_tree(const std::vector<Light>& lights, const LightTreeBuildOptions& opt) {
  std::vector<EmitterBounds> eb = emitter_bounds(lights);
  double scale = normalize_emitter_energies(eb);
  BinaryLightTree bt = build_binary_light_tree(eb, opt);
  LightTree t = collapse_light_tree(bt, eb);
  t.energy_scale = scale;
  return t;
}

} // namespace canopy

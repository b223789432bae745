// Surface queries for finger contact: entry, tracking (the frictionless god-object) and
// projection back onto the surface, per shape kind. See surface.hpp.
#include "graspsim/engine/surface.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>

#include "graspsim/engine/collision.hpp"

namespace graspsim {
namespace {

constexpr double kTol = 1e-10;    // m: on-plane / in-polygon tolerance (shapes are cm to m)
constexpr int kMaxWalk = 32;      // iterations of the god-object walk (each adds or drops a
                                  // plane or reaches its goal; a corner needs about 4)

// ---------------------------------------------------------------------------------------------
// Analytic shapes: signed distance to the core shape (grown by r in the callers), closest points.

// Closest point of the solid cylinder (radius R, half length L) to x, and whether x is inside.
Vec3 cylinder_closest(double R, double L, const Vec3& x, bool& inside) {
  const double rho = std::hypot(x.x(), x.y());
  inside = rho <= R && std::abs(x.z()) <= L;
  Vec3 c = x;
  if (rho > R) { c.x() *= R / rho; c.y() *= R / rho; }
  c.z() = std::clamp(x.z(), -L, L);
  return c;
}

// Signed distance from x to the surface of the core shape (negative inside): convex in x, so
// along a path it is a convex function of the path parameter.
double core_signed_distance(const Shape& s, const Vec3& x) {
  switch (s.kind) {
    case ShapeKind::kSphere: return x.norm() - s.radius;
    case ShapeKind::kCapsule: {
      const Vec3 q(0.0, 0.0, std::clamp(x.z(), -s.half_length, s.half_length));
      return (x - q).norm() - s.radius;
    }
    case ShapeKind::kCylinder: {
      bool inside = false;
      const Vec3 c = cylinder_closest(s.radius, s.half_length, x, inside);
      if (!inside) return (x - c).norm();
      const double rho = std::hypot(x.x(), x.y());
      return -std::min(s.radius - rho, s.half_length - std::abs(x.z()));
    }
    default: return kInfinity;
  }
}

// Unit vector of v, or `fallback` when v is (nearly) zero or points against `fallback`'s side
// (a HIP pressed past the centre or axis keeps the side it entered: no push-through).
Vec3 direction_keeping_side(const Vec3& v, const Vec3& fallback) {
  const double n = v.norm();
  if (n <= kTol || v.dot(fallback) <= 0.0) return fallback;
  return v / n;
}

// Tracking on a sphere or capsule: the closest point of the grown surface, about the closest
// point q of the core (centre or axis segment). Outside the grown surface the contact ends.
bool track_round(const Shape& s, double r, const Vec3& prev_normal, const Vec3& x, SurfaceTrack& out) {
  const double L = s.kind == ShapeKind::kCapsule ? s.half_length : 0.0;
  const Vec3 q(0.0, 0.0, std::clamp(x.z(), -L, L));
  const double grown = s.radius + r;
  const Vec3 n = direction_keeping_side(x - q, prev_normal);
  const double depth = grown - (x - q).dot(n);
  if (!(depth > 0.0)) return false;
  out.normal = n;
  out.point = q + grown * n;
  out.depth = depth;
  out.features.count = 1;
  out.features.ids[0] = s.kind == ShapeKind::kSphere ? 0 : (x.z() > L ? 1 : (x.z() < -L ? 2 : 0));
  return true;
}

// Tracking on a cylinder (radius R, half length L) grown by r, exactly: outside the core the
// closest point (side, cap or, for a pad, the rounded rim) is unique; inside the core the
// feature held decides (side or cap: history, so a deep finger never jumps to another side),
// and a contact arriving from a rim takes the core surface it is shallowest under, the one it
// has just crossed.
bool track_cylinder(const Shape& s, double r, int feature, const Vec3& prev_normal, const Vec3& x,
                    SurfaceTrack& out) {
  const double R = s.radius, L = s.half_length;
  bool inside = false;
  const Vec3 c = cylinder_closest(R, L, x, inside);
  const double rho = std::hypot(x.x(), x.y());
  out.features.count = 1;
  if (!inside) {
    const double dist = (x - c).norm();
    if (!(dist < r)) return false;   // r = 0: outside the core is outside the body
    out.normal = (x - c) / dist;
    out.point = c + r * out.normal;
    out.depth = r - dist;
    const bool on_side = std::abs(x.z()) <= L, on_cap = rho <= R;
    out.features.ids[0] = on_side ? 0 : (on_cap ? (x.z() > 0.0 ? 1 : 2) : (x.z() > 0.0 ? 3 : 4));
    return true;
  }
  if (feature >= 3) {   // from a rim into the core: the surface just crossed
    feature = (R - rho < L - std::abs(x.z())) ? 0 : (x.z() > 0.0 ? 1 : 2);
  }
  out.features.ids[0] = feature;
  if (feature == 0) {
    Vec3 side_prev(prev_normal.x(), prev_normal.y(), 0.0);
    if (side_prev.norm() <= kTol) side_prev = Vec3::UnitX();
    const Vec3 u = direction_keeping_side(Vec3(x.x(), x.y(), 0.0), side_prev.normalized());
    out.normal = u;
    out.point = Vec3((R + r) * u.x(), (R + r) * u.y(), x.z());
    out.depth = R + r - u.dot(Vec3(x.x(), x.y(), 0.0));
  } else {
    const double sign = feature == 1 ? 1.0 : -1.0;
    out.normal = Vec3(0.0, 0.0, sign);
    out.point = Vec3(x.x(), x.y(), sign * (L + r));
    out.depth = L + r - sign * x.z();
  }
  return out.depth > 0.0;
}

// First entry of the path a -> b into {phi <= r} for a convex signed distance phi: the minimum of
// phi along the path by golden section (stopping at the first probe inside), then bisection for
// the first crossing. About 110 evaluations at most; t to 1e-15.
std::optional<double> convex_entry_t(const Shape& s, double r, const Vec3& a, const Vec3& b) {
  const auto g = [&](double t) { return core_signed_distance(s, a + t * (b - a)) - r; };
  if (g(0.0) <= 0.0) return g(1.0) <= 0.0 ? std::optional<double>(0.0) : std::nullopt;
  double hi = -1.0;
  if (g(1.0) <= 0.0) {
    hi = 1.0;
  } else {
    constexpr double phi = 0.6180339887498949;
    double lo = 0.0, up = 1.0;
    double x1 = up - phi * (up - lo), x2 = lo + phi * (up - lo);
    double g1 = g(x1), g2 = g(x2);
    for (int i = 0; i < 80 && hi < 0.0; ++i) {
      if (g1 <= 0.0) { hi = x1; break; }
      if (g2 <= 0.0) { hi = x2; break; }
      if (g1 < g2) { up = x2; x2 = x1; g2 = g1; x1 = up - phi * (up - lo); g1 = g(x1); }
      else { lo = x1; x1 = x2; g1 = g2; x2 = lo + phi * (up - lo); g2 = g(x2); }
    }
    if (hi < 0.0) return std::nullopt;   // the path passes the body by
  }
  double lo = 0.0;   // g(lo) > 0, g(hi) <= 0
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    (g(mid) <= 0.0 ? hi : lo) = mid;
  }
  return hi;
}

// ---------------------------------------------------------------------------------------------
// Polygonal surfaces: the god-object walk.

const Vec3& face_normal(const SurfaceGeometry& g, int f) { return g.face(f).normal; }

double plane_gap(const SurfaceGeometry& g, double r, int f, const Vec3& x) {
  const auto& F = g.face(f);
  return F.normal.dot(x) - (F.offset + r);   // > 0 outside the face's (offset) plane
}

// x (on face f's plane grown by r) within the face's polygon, grown in-plane by `slack`.
bool in_polygon(const SurfaceGeometry& g, double r, int f, const Vec3& x, double slack) {
  const auto& F = g.face(f);
  const Vec3 q = x - r * F.normal;
  for (int i = 0; i < F.count; ++i) {
    if (g.edge_normal(F.first + i).dot(q - g.corner(F.first + i)) < -slack) return false;
  }
  return true;
}

bool holds(const Features& S, int f) {
  for (int i = 0; i < S.count; ++i) if (S.ids[i] == f) return true;
  return false;
}

void remove_at(Features& S, int i) {
  for (int j = i; j + 1 < S.count; ++j) S.ids[j] = S.ids[j + 1];
  --S.count;
}

// Closest point to h on the intersection of the planes of S (grown by r), and their Lagrange
// multipliers: goal = h + sum lambda_i n_i. Planes that are (nearly) dependent are dropped.
Vec3 constrained_goal(const SurfaceGeometry& g, double r, Features& S, const Vec3& h,
                      std::array<double, kMaxFeatures>& lambda) {
  for (;;) {
    if (S.count == 0) return h;
    Eigen::Matrix3d G = Eigen::Matrix3d::Identity();
    Vec3 rhs = Vec3::Zero();
    for (int i = 0; i < S.count; ++i) {
      const auto& Fi = g.face(S.ids[i]);
      rhs[i] = Fi.offset + r - Fi.normal.dot(h);
      for (int j = 0; j < S.count; ++j) G(i, j) = Fi.normal.dot(g.face(S.ids[j]).normal);
    }
    Vec3 l = Vec3::Zero();
    if (S.count == 1) {
      l[0] = rhs[0];
    } else if (S.count == 2) {
      const double det = 1.0 - G(0, 1) * G(0, 1);
      if (det < 1e-9) { remove_at(S, 1); continue; }   // parallel planes: keep the first
      l[0] = (rhs[0] - G(0, 1) * rhs[1]) / det;
      l[1] = (rhs[1] - G(0, 1) * rhs[0]) / det;
    } else {
      const double det = G.determinant();
      if (std::abs(det) < 1e-9) { remove_at(S, 2); continue; }
      l = G.inverse() * rhs;
    }
    Vec3 goal = h;
    for (int i = 0; i < S.count; ++i) {
      lambda[i] = l[i];
      goal += l[i] * g.face(S.ids[i]).normal;
    }
    return goal;
  }
}

// The edge face a shares with face b (the slot in a's corners), or -1.
int shared_edge(const SurfaceGeometry& g, int a, int b) {
  const auto& A = g.face(a);
  for (int j = 0; j < A.count; ++j) if (g.neighbour(A.first + j) == b) return A.first + j;
  return -1;
}

// Whether faces a and b meet at a convex edge (b bends away below a's plane).
bool convex_edge(const SurfaceGeometry& g, int a, int b) {
  const int e = shared_edge(g, a, b);
  return e >= 0 && g.edge_normal(e).dot(g.face(b).normal) < -1e-9;
}

// A pad at the convex edge between faces a and b: the grown surface there is the cylinder of
// radius r about the edge (the exact Minkowski sum). With e the HIP's closest point on the
// edge and v = HIP - e = alpha n_a + beta n_b (+ along the edge): both >= 0, the HIP is in the
// edge's wedge of normals, SP = e + r v/|v| (returns 0; -1 when |v| >= r, the HIP beyond the
// grown surface: the contact ends, unless `glued`); else SP goes to the offset edge of the face
// on the HIP's side, e + r n (returns 1, `face` set). Continuous at the wedge's sides.
int rounded_edge(const SurfaceGeometry& g, double r, int a, int b, const Vec3& h, bool glued,
                 Vec3& p, int& face) {
  const int e = shared_edge(g, a, b);
  const auto& A = g.face(a);
  const Vec3& c0 = g.corner(e);
  const Vec3& c1 = g.corner(A.first + (e - A.first + 1) % A.count);
  const Vec3 t = c1 - c0;
  const Vec3 on_edge = c0 + std::clamp((h - c0).dot(t) / t.squaredNorm(), 0.0, 1.0) * t;
  const Vec3 v = h - on_edge;
  const Vec3& na = A.normal;
  const Vec3& nb = g.face(b).normal;
  const double c = na.dot(nb), va = v.dot(na), vb = v.dot(nb);
  const double alpha = va - c * vb, beta = vb - c * va;   // times 1 / (1 - c^2) > 0
  if (alpha < 0.0 || beta < 0.0) {
    face = alpha < 0.0 ? b : a;
    p = on_edge + r * g.face(face).normal;
    return 1;
  }
  const double dist = v.norm();
  if (!glued && !(dist < r)) return -1;
  p = on_edge + r * (dist > kTol ? Vec3(v / dist) : Vec3((na + nb).normalized()));
  return 0;
}

// The walk. From p on the surface held by S, towards h: drop the planes h is above (negative
// multipliers; `glued` keeps at least one), move towards the closest point on the remaining
// planes, stop where the path first meets another face (from outside: the face is added) or
// leaves the polygon of a held face (the face is dropped and, if none is left, the neighbour
// across that edge is taken: for a pad, the point moves from the one offset plane to the other
// over the edge, 2 r sin(angle / 2)). Every move goes towards a closer point (the distance to h
// decreases), faces behind the point are never met (no push-through), and at most kMaxWalk
// iterations run. Returns whether p is held (false: it reached h in free space).
bool walk(const SurfaceGeometry& g, double r, bool glued, const Vec3& h, Vec3& p, Features& S) {
  int dropped = -1;
  if (r > 0.0 && S.count == 2 && convex_edge(g, S.ids[0], S.ids[1])) {
    // Held on a pad's rounded edge at the last tick: still there, or back onto a face.
    int face = -1;
    const int where = rounded_edge(g, r, S.ids[0], S.ids[1], h, glued, p, face);
    if (where == 0) return true;
    if (where < 0) { S.count = 0; return false; }
    S.count = 1;
    S.ids[0] = face;
  }
  for (int iter = 0; iter < kMaxWalk; ++iter) {
    std::array<double, kMaxFeatures> lambda{};
    Vec3 goal = constrained_goal(g, r, S, h, lambda);
    int worst = -1;
    for (int i = 0; i < S.count; ++i) {
      if (lambda[i] < -kTol && (worst < 0 || lambda[i] < lambda[worst])) worst = i;
    }
    if (worst >= 0 && (!glued || S.count > 1)) {
      dropped = S.ids[worst];
      remove_at(S, worst);
      continue;
    }
    const Vec3 d = goal - p;
    if (d.squaredNorm() <= kTol * kTol) { p = goal; break; }
    // Where the move leaves a held face's polygon.
    double t_exit = 1.0;
    int exit_slot = -1, exit_edge = -1;
    for (int i = 0; i < S.count; ++i) {
      const auto& F = g.face(S.ids[i]);
      const Vec3 q = p - r * F.normal;
      for (int e = 0; e < F.count; ++e) {
        const Vec3& m = g.edge_normal(F.first + e);
        const double rate = m.dot(d);
        if (rate >= 0.0) continue;
        const double t = std::max(0.0, m.dot(q - g.corner(F.first + e))) / -rate;
        if (t < t_exit) { t_exit = t; exit_slot = i; exit_edge = F.first + e; }
      }
    }
    // The first face met (entered from outside) before that, among the rings of the held and
    // the last dropped faces; a tie with the exit goes to the face met (a concave edge).
    double t_hit = t_exit;
    int hit = -1;
    const auto try_ring = [&](int f) {
      const auto& F = g.face(f);
      for (int k = 0; k < F.ring_count; ++k) {
        const int c = g.ring(F.ring_first + k);
        if (holds(S, c)) continue;
        const double sp = plane_gap(g, r, c, p), sg = plane_gap(g, r, c, goal);
        if (sp < -kTol || !(sg < -kTol)) continue;   // behind it, or not entering it
        const double t = std::max(sp, 0.0) / (sp - sg);
        if (t > t_hit || (t == t_hit && hit >= 0 && c > hit)) continue;
        if (!in_polygon(g, r, c, p + t * d, kTol)) continue;
        // Met on one of its edges while moving out past that edge (from a convex edge onto the
        // next face, below the first one's plane extended): not entered.
        bool leaving = false;
        const Vec3 q = p + t * d - r * face_normal(g, c);
        for (int j = 0; j < g.face(c).count && !leaving; ++j) {
          const int e = g.face(c).first + j;
          leaving = std::abs(g.edge_normal(e).dot(q - g.corner(e))) <= kTol &&
                  g.edge_normal(e).dot(d) < -1e-9 * d.norm();
        }
        if (leaving) continue;
        t_hit = t;
        hit = c;
      }
    };
    for (int i = 0; i < S.count; ++i) try_ring(S.ids[i]);
    if (dropped >= 0) try_ring(dropped);
    if (hit >= 0) {
      p += t_hit * d;
      if (S.count == kMaxFeatures) break;   // held by three planes already: stays
      S.ids[S.count++] = hit;
      continue;
    }
    if (exit_slot >= 0) {
      p += t_exit * d;
      const int left = S.ids[exit_slot];
      remove_at(S, exit_slot);
      const int dropped_before = dropped;
      dropped = left;
      const int across = g.neighbour(exit_edge);
      if (S.count == 0 && across >= 0 && across == dropped_before && t_exit * d.norm() <= kTol &&
          plane_gap(g, r, left, h) < 0.0 && plane_gap(g, r, across, h) < 0.0) {
        // Back at once over the edge just crossed, the HIP below both faces: the god-object
        // stays on the edge. For a point (r = 0) both planes hold it there (the multipliers
        // release it). For a pad the HIP is in the convex edge's wedge of normals, where the
        // grown surface is the edge's cylinder of radius r: SP lies on it (or the contact
        // ends, the HIP beyond it).
        if (r > 0.0) {
          int face = -1;
          const int where = rounded_edge(g, r, across, left, h, glued, p, face);
          if (where < 0) { S.count = 0; break; }
          S.count = where == 0 ? 2 : 1;
          S.ids[0] = where == 0 ? across : face;
          S.ids[1] = left;
          if (where == 0) break;
          continue;
        }
        S.count = 2;
        S.ids[0] = left;
        S.ids[1] = across;
        continue;
      }
      if (S.count == 0 && across >= 0) {
        p += r * (g.face(across).normal - g.face(left).normal);
        S.count = 1;
        S.ids[0] = across;
      } else if (S.count == 0 && glued) {   // an open edge: stay on it
        S.count = 1;
        S.ids[0] = left;
        break;
      }
      continue;
    }
    p = goal;
    if (S.count == 0) break;   // reached h unobstructed: free
  }
  return S.count > 0;
}

// Face f's entry test for the path a -> b: the plane (grown by r) crossed from outside, at the
// crossing inside the polygon grown in-plane by r + kTol. Keeps the earliest crossing, ties to
// the lower face index (the order a linear scan over the faces gives).
void try_crossing(const SurfaceGeometry& g, double r, int f, const Vec3& a, const Vec3& b, double& best,
                  int& face) {
  const double sa = plane_gap(g, r, f, a), sb = plane_gap(g, r, f, b);
  if (sa < -kTol || !(sb < 0.0)) return;   // a on the plane (to rounding) counts as outside
  const double t = std::max(sa, 0.0) / (sa - sb);
  if (t > best || (t == best && f > face)) return;
  if (!in_polygon(g, r, f, a + t * (b - a), r + kTol)) return;
  best = t;
  face = f;
}

// Whether the segment a -> b meets the box [lo - e, hi + e] (slabs, closed).
bool segment_meets_box(const Vec3& a, const Vec3& d, const Vec3& lo, const Vec3& hi, double e) {
  double t0 = 0.0, t1 = 1.0;
  for (int j = 0; j < 3; ++j) {
    const double l = lo[j] - e, h = hi[j] + e;
    if (d[j] == 0.0) {
      if (a[j] < l || a[j] > h) return false;
      continue;
    }
    double u = (l - a[j]) / d[j], v = (h - a[j]) / d[j];
    if (u > v) std::swap(u, v);
    t0 = std::max(t0, u);
    t1 = std::min(t1, v);
    if (t0 > t1) return false;
  }
  return true;
}

// The first face crossed by a -> b (try_crossing over every face), found through the face tree:
// only faces in leaves whose grown boxes the segment meets are tried. The boxes hold each face's
// whole entry region (see SurfaceGeometry::BvhNode) with 1e-9 m to spare for rounding, and the
// tie rule does not depend on the visiting order, so the result is the linear scan's, bit for
// bit. A fixed stack: no allocation.
void first_crossing(const SurfaceGeometry& g, double r, const Vec3& a, const Vec3& b, double& best, int& face) {
  const auto& nodes = g.bvh();
  if (nodes.empty()) return;
  const Vec3 d = b - a;
  std::array<int, 64> stack{};
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const SurfaceGeometry::BvhNode& node = nodes[stack[--top]];
    const double grow = node.kappa * (r + kTol) + r + 1e-9;   // m
    if (!segment_meets_box(a, d, node.lo, node.hi, grow)) continue;
    if (node.count > 0) {
      for (int i = 0; i < node.count; ++i) try_crossing(g, r, g.bvh_face(node.first + i), a, b, best, face);
      continue;
    }
    stack[top++] = node.right;
    stack[top++] = node.first;
  }
}

// Face plane of a box as a SurfaceTrack, if the HIP is below it and over the face (the existing
// box rule, kept exactly: faces offset by r, edges square; off a face's edge the contact ends).
bool track_box(const Shape& s, double r, int face, const Vec3& x, SurfaceTrack& out) {
  const Face f = box_face(s.half_extents, face);
  const double depth = f.offset + r - f.normal.dot(x);
  if (!(depth > 0.0) || !within_face(s.half_extents, face, x)) return false;
  out.point = x + depth * f.normal;
  out.normal = f.normal;
  out.depth = depth;
  out.features.count = 1;
  out.features.ids[0] = face;
  return true;
}

}  // namespace

SurfaceGeometry::SurfaceGeometry(const Shape& shape) : shape_(shape) {
  if (shape.kind != ShapeKind::kConvex && shape.kind != ShapeKind::kMesh) return;
  // Faces as corner lists: the hull's polygons, or the mesh's triangles.
  std::vector<Vec3> vertices;
  std::vector<std::vector<int>> polys;
  std::vector<std::pair<Vec3, double>> planes;
  if (shape.kind == ShapeKind::kConvex) {
    if (!shape.hull) throw std::invalid_argument("convex shape without its hull");
    vertices = shape.hull->vertices;
    for (const auto& f : shape.hull->faces) {
      polys.push_back(f.vertices);
      planes.emplace_back(f.normal, f.offset);
    }
  } else {
    if (!shape.mesh) throw std::invalid_argument("mesh shape without its triangles");
    vertices = shape.mesh->vertices;
    for (const auto& t : shape.mesh->triangles) {
      polys.push_back({t[0], t[1], t[2]});
      const Vec3 n = (vertices[t[1]] - vertices[t[0]]).cross(vertices[t[2]] - vertices[t[0]]);
      if (!(n.norm() > 0.0) || !n.allFinite()) {
        // A degenerate triangle (no area): a plane no path ever crosses, never held.
        planes.emplace_back(Vec3::Zero(), kInfinity);
      } else {
        planes.emplace_back(n.normalized(), n.normalized().dot(vertices[t[0]]));
      }
    }
  }
  // Directed edges (a, b, face, corner slot), sorted, to find the face across each edge.
  std::vector<std::tuple<int, int, int, int>> edges;
  for (std::size_t f = 0; f < polys.size(); ++f) {
    const auto& vs = polys[f];
    for (std::size_t i = 0; i < vs.size(); ++i) {
      edges.emplace_back(vs[i], vs[(i + 1) % vs.size()], static_cast<int>(f), static_cast<int>(i));
    }
  }
  std::sort(edges.begin(), edges.end());
  std::vector<std::vector<int>> vertex_faces(vertices.size());
  for (std::size_t f = 0; f < polys.size(); ++f) {
    for (int v : polys[f]) vertex_faces[v].push_back(static_cast<int>(f));
  }
  for (std::size_t f = 0; f < polys.size(); ++f) {
    const auto& vs = polys[f];
    PolyFace F;
    F.normal = planes[f].first;
    F.offset = planes[f].second;
    F.first = static_cast<int>(corners_.size());
    F.count = static_cast<int>(vs.size());
    for (std::size_t i = 0; i < vs.size(); ++i) {
      const int a = vs[i], b = vs[(i + 1) % vs.size()];
      corners_.push_back(vertices[a]);
      const Vec3 m = F.normal.cross(vertices[b] - vertices[a]);
      edge_normals_.push_back(m.norm() > 0.0 ? Vec3(m.normalized()) : Vec3::Zero());
      const auto it = std::lower_bound(edges.begin(), edges.end(), std::make_tuple(b, a, -1, -1));
      neighbours_.push_back(it != edges.end() && std::get<0>(*it) == b && std::get<1>(*it) == a
                                ? std::get<2>(*it) : -1);
    }
    std::vector<int> ring;
    for (int v : vs) for (int h : vertex_faces[v]) if (h != static_cast<int>(f)) ring.push_back(h);
    std::sort(ring.begin(), ring.end());
    ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
    F.ring_first = static_cast<int>(ring_.size());
    F.ring_count = static_cast<int>(ring.size());
    ring_.insert(ring_.end(), ring.begin(), ring.end());
    faces_.push_back(F);
  }
  // The face tree (first_crossing): faces with a plane, their centroids, a 1 / sin(angle / 2)
  // per face from its sharpest corner.
  std::vector<Vec3> centroids(faces_.size(), Vec3::Zero());
  for (int f = 0; f < static_cast<int>(faces_.size()); ++f) {
    const PolyFace& F = faces_[f];
    if (!std::isfinite(F.offset)) continue;
    for (int i = 0; i < F.count; ++i) centroids[f] += corners_[F.first + i] / F.count;
    bvh_faces_.push_back(f);
  }
  if (!bvh_faces_.empty()) {
    bvh_.reserve(2 * bvh_faces_.size());
    build_bvh(0, static_cast<int>(bvh_faces_.size()), centroids);
  }
}

int SurfaceGeometry::build_bvh(int first, int count, const std::vector<Vec3>& centroids) {
  constexpr int kLeafFaces = 4;
  const int index = static_cast<int>(bvh_.size());
  bvh_.push_back(BvhNode{Vec3::Constant(kInfinity), Vec3::Constant(-kInfinity), 1.0, first, count, -1});
  Vec3 clo = Vec3::Constant(kInfinity), chi = Vec3::Constant(-kInfinity);
  for (int i = first; i < first + count; ++i) {
    const PolyFace& F = faces_[bvh_faces_[i]];
    BvhNode& node = bvh_[index];
    for (int k = 0; k < F.count; ++k) {
      const Vec3& c = corners_[F.first + k];
      node.lo = node.lo.cwiseMin(c);
      node.hi = node.hi.cwiseMax(c);
      const Vec3 u = corners_[F.first + (k + F.count - 1) % F.count] - c;
      const Vec3 v = corners_[F.first + (k + 1) % F.count] - c;
      const double cos_angle = u.dot(v) / (u.norm() * v.norm());
      const double sin_half = std::sqrt(std::max(0.0, 0.5 * (1.0 - cos_angle)));
      node.kappa = std::max(node.kappa, sin_half > 0.0 ? 1.0 / sin_half : kInfinity);
    }
    clo = clo.cwiseMin(centroids[bvh_faces_[i]]);
    chi = chi.cwiseMax(centroids[bvh_faces_[i]]);
  }
  if (count <= kLeafFaces) return index;
  int axis = 0;
  (chi - clo).maxCoeff(&axis);
  const int half = count / 2;
  // Median by centroid along the axis, ties by face index: a total order, so the tree does not
  // depend on the sort's implementation.
  std::sort(bvh_faces_.begin() + first, bvh_faces_.begin() + first + count, [&](int p, int q) {
    const double cp = centroids[p][axis], cq = centroids[q][axis];
    return cp < cq || (cp == cq && p < q);
  });
  bvh_[index].count = 0;
  const int left = build_bvh(first, half, centroids);
  const int right = build_bvh(first + half, count - half, centroids);
  bvh_[index].first = left;
  bvh_[index].right = right;
  return index;
}

std::optional<SurfaceEntry> surface_entry(const SurfaceGeometry& g, double r, const Vec3& a,
                                          const Vec3& b) {
  const Shape& s = g.shape();
  switch (s.kind) {
    case ShapeKind::kBox: {
      const auto e = box_entry(s.half_extents + Vec3::Constant(r), a, b);
      if (!e) return std::nullopt;
      return SurfaceEntry{e->point, box_face(s.half_extents, e->face).normal, e->t, Features{1, {e->face, 0, 0}}};
    }
    case ShapeKind::kSphere:
    case ShapeKind::kCapsule:
    case ShapeKind::kCylinder: {
      const auto t = convex_entry_t(s, r, a, b);
      if (!t) return std::nullopt;
      // Already inside at a (the body moved onto the finger, or the first tick): from b, as
      // the box does; else the entry point, nudged 1e-9 m along the path so it is inside.
      const bool from_inside = core_signed_distance(s, a) - r <= 0.0;
      const Vec3 x = from_inside ? b : Vec3(a + *t * (b - a));
      // The entry point lies on the grown surface (to the bisection's tolerance): the closest
      // point there gives SP, normal and feature. No history yet: the outward direction from
      // the core's centre stands in for it.
      SurfaceTrack tr;
      const Vec3 hint = x.norm() > kTol ? Vec3(x.normalized()) : Vec3(-(b - a).normalized());
      int feature = 0;
      if (s.kind == ShapeKind::kCylinder && std::abs(x.z()) > s.half_length - kTol &&
          s.half_length - std::abs(x.z()) < s.radius - std::hypot(x.x(), x.y())) {
        feature = x.z() > 0.0 ? 1 : 2;
      }
      const Vec3 inward = from_inside ? x : Vec3(x + 1e-9 * (b - a).normalized());
      const bool ok = s.kind == ShapeKind::kCylinder ? track_cylinder(s, r, feature, hint, inward, tr)
                                                     : track_round(s, r, hint, inward, tr);
      if (!ok) return std::nullopt;
      return SurfaceEntry{tr.point, tr.normal, *t, tr.features};
    }
    case ShapeKind::kConvex:
    case ShapeKind::kMesh: {
      // The first face plane (grown by r) crossed from outside inside its polygon
      // (for a pad grown in-plane by r, covering the offset faces' gaps at convex edges; the
      // point is then moved onto the polygon). A path starting inside a convex polyhedron (the
      // body moved onto the finger, or the first tick) takes the face nearest to b, as a box
      // does; inside a mesh it enters nothing (no inside test for a non-convex mesh).
      double best = kInfinity;
      int face = -1;
      if (s.kind == ShapeKind::kConvex) {
        double gap_a = -kInfinity, gap_b = -kInfinity;
        int nearest = -1;
        for (int f = 0; f < g.face_count(); ++f) {
          gap_a = std::max(gap_a, plane_gap(g, r, f, a));
          const double gb = plane_gap(g, r, f, b);
          if (gb > gap_b) { gap_b = gb; nearest = f; }
        }
        if (gap_a <= 0.0) {
          if (!(gap_b <= 0.0) || nearest < 0) return std::nullopt;   // started inside and left
          face = nearest;
          best = 0.0;
        }
      }
      const bool from_inside = face >= 0;
      if (!from_inside) first_crossing(g, r, a, b, best, face);
      if (face < 0) return std::nullopt;
      const auto& F = g.face(face);
      Vec3 q = (from_inside ? b : Vec3(a + best * (b - a))) - r * F.normal;
      for (int pass = 0; pass < 2; ++pass) {
        for (int i = 0; i < F.count; ++i) {
          const Vec3& m = g.edge_normal(F.first + i);
          const double gap = m.dot(q - g.corner(F.first + i));
          if (gap < 0.0) q -= gap * m;
        }
      }
      q += (F.offset - F.normal.dot(q)) * F.normal;   // exactly on the plane
      return SurfaceEntry{q + r * F.normal, F.normal, best, Features{1, {face, 0, 0}}};
    }
  }
  return std::nullopt;
}

bool surface_track(const SurfaceGeometry& g, double r, const Features& features, const Vec3& sp,
                   const Vec3& normal, const Vec3& hip, SurfaceTrack& out) {
  const Shape& s = g.shape();
  switch (s.kind) {
    case ShapeKind::kBox: return track_box(s, r, features.ids[0], hip, out);
    case ShapeKind::kSphere:
    case ShapeKind::kCapsule: return track_round(s, r, normal, hip, out);
    case ShapeKind::kCylinder: return track_cylinder(s, r, features.ids[0], normal, hip, out);
    case ShapeKind::kConvex:
    case ShapeKind::kMesh: {
      Vec3 p = sp;
      Features S = features;
      if (!walk(g, r, false, hip, p, S)) return false;
      const Vec3 d = p - hip;
      const double depth = d.norm();
      if (!(depth > 0.0)) return false;   // on the surface: touching, no force
      out.point = p;
      out.depth = depth;
      // One plane: its normal (exactly); held by an edge or a corner (or stopped on one): the
      // direction from the HIP to SP, which is the force's direction.
      const Vec3& n0 = g.face(S.ids[0]).normal;
      out.normal = S.count == 1 && n0.dot(d) >= depth * (1.0 - 1e-12) ? n0 : Vec3(d / depth);
      out.features = S;
      return true;
    }
  }
  return false;
}

Vec3 surface_project(const SurfaceGeometry& g, double r, const SurfaceTrack& at, const Vec3& target) {
  const Shape& s = g.shape();
  switch (s.kind) {
    case ShapeKind::kBox: return target;
    case ShapeKind::kSphere:
    case ShapeKind::kCapsule: {
      const double L = s.kind == ShapeKind::kCapsule ? s.half_length : 0.0;
      const Vec3 q(0.0, 0.0, std::clamp(target.z(), -L, L));
      return q + (s.radius + r) * direction_keeping_side(target - q, at.normal);
    }
    case ShapeKind::kCylinder: {
      bool inside = false;
      const Vec3 c = cylinder_closest(s.radius, s.half_length, target, inside);
      const double dist = (target - c).norm();
      if (!inside && dist > kTol) return c + r * (target - c) / dist;
      // Inside the core (or on it): onto the surface of SP's feature, as tracking would.
      SurfaceTrack tr;
      const Vec3 deeper = target - 1e-9 * at.normal;
      if (track_cylinder(s, r, at.features.ids[0], at.normal, deeper, tr)) return tr.point;
      return at.point;
    }
    case ShapeKind::kConvex:
    case ShapeKind::kMesh: {
      Vec3 p = at.point;
      Features S = at.features;
      walk(g, r, true, target, p, S);
      return p;
    }
  }
  return target;
}

}  // namespace graspsim

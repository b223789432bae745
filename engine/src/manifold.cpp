// Polyhedron-polyhedron contact manifolds: separating axes, then reference/incident face clipping.
#include "graspsim/engine/manifold.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace graspsim {
namespace {

// Feature keys: a fixed mix of small integers (boost::hash_combine's rule), so the same features
// give the same key at every step and on every machine.
std::uint64_t combine(std::uint64_t h, std::uint64_t v) {
  return h ^ (v + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2));
}

// Features of A (owner 0) and B (owner 1): a vertex, an edge (its two vertices, either order)
// or a face, by index in that body's hull. A clip point is where a feature of A meets one of B;
// its key combines the two, A's first, so it does not depend on which body gives the reference
// face: A's vertex v inside B's face f is the same point whether it was kept as a vertex of A's
// incident face or cut out of B's incident face at the corner v of A's reference face.
enum : std::uint64_t { kVertex = 1, kEdge = 2, kFace = 3, kSidePlane = 4 };

std::uint64_t feature(std::uint64_t owner, std::uint64_t kind, std::uint64_t i, std::uint64_t j = 0) {
  return combine(combine(combine(combine(7, owner), kind), i), j);
}

std::uint64_t edge_feature(std::uint64_t owner, int v, int w) {
  return feature(owner, kEdge, static_cast<std::uint64_t>(std::min(v, w)), static_cast<std::uint64_t>(std::max(v, w)));
}

std::uint64_t point_key(std::uint64_t owner_1, std::uint64_t f1, std::uint64_t f2) {
  // f1 belongs to owner_1, f2 to the other body.
  return owner_1 == 0 ? combine(combine(5, f1), f2) : combine(combine(5, f2), f1);
}

struct FaceQuery {
  double separation = -std::numeric_limits<double>::infinity();   // m
  int face = -1;
};

// The face of `p` (vertices in world `wp`, pose R, x) whose plane the other body's vertices `wq`
// lie deepest outside of: separation = max over faces of min over q of (n . q - plane).
FaceQuery query_faces(const ConvexPolyhedron& p, const Vec3& x, const Mat3& r, const std::vector<Vec3>& wq) {
  FaceQuery best;
  for (int f = 0; f < static_cast<int>(p.faces.size()); ++f) {
    const Vec3 n = r * p.faces[f].normal;
    const double plane = n.dot(x) + p.faces[f].offset;
    double lowest = std::numeric_limits<double>::infinity();
    for (const Vec3& q : wq) lowest = std::min(lowest, n.dot(q));
    if (lowest - plane > best.separation) {
      best.separation = lowest - plane;
      best.face = f;
    }
  }
  return best;
}

// Closest points of the segments p0-p1 and q0-q1; false when they are parallel or the closest
// points of the two lines fall outside either segment (then the edges do not meet as edges).
// Gregorius' Gauss-map test: the arcs a-b (normals of A's two faces at its edge) and c-d (the
// negated normals of B's two faces at its edge) cross on the unit sphere, so the two edges form
// a face of the Minkowski difference A - B and their cross product is a candidate axis.
bool minkowski_face(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const Vec3 bxa = b.cross(a), dxc = d.cross(c);
  const double cba = c.dot(bxa), dba = d.dot(bxa), adc = a.dot(dxc), bdc = b.dot(dxc);
  return cba * dba < 0.0 && adc * bdc < 0.0 && cba * bdc > 0.0;
}

bool edge_closest(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1, Vec3& cp, Vec3& cq) {
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.dot(d1), e = d2.dot(d2), b = d1.dot(d2), c = d1.dot(r), f = d2.dot(r);
  const double denom = a * e - b * b;
  if (denom <= 1e-12 * a * e) return false;
  const double s = (b * f - c * e) / denom, t = (a * f - b * c) / denom;
  if (s < 0.0 || s > 1.0 || t < 0.0 || t > 1.0) return false;
  cp = p0 + s * d1;
  cq = q0 + t * d2;
  return true;
}

}  // namespace

HullEdges hull_edges(const ConvexPolyhedron& hull) {
  HullEdges h;
  h.hull = &hull;
  for (const PolyFace& f : hull.faces) {
    const int n = static_cast<int>(f.vertices.size());
    h.max_face_vertices = std::max(h.max_face_vertices, n);
    for (int i = 0; i < n; ++i) {
      const int a = f.vertices[i], b = f.vertices[(i + 1) % n];
      const int here = static_cast<int>(&f - hull.faces.data());
      // Each edge of a closed hull appears once as a < b.
      if (a < b) h.edges.push_back({a, b, here, f.neighbours.empty() ? -1 : f.neighbours[i]});
    }
  }
  std::sort(h.edges.begin(), h.edges.end());
  h.edges.erase(std::unique(h.edges.begin(), h.edges.end()), h.edges.end());
  return h;
}

void ManifoldScratch::reserve_for(const HullEdges& a, const HullEdges& b) {
  const std::size_t va = a.hull->vertices.size(), vb = b.hull->vertices.size();
  world_a.reserve(std::max(world_a.capacity(), va));
  world_b.reserve(std::max(world_b.capacity(), vb));
  // Clipping an n-gon by m planes leaves at most n + m vertices.
  const std::size_t clip = static_cast<std::size_t>(a.max_face_vertices + b.max_face_vertices) + 1;
  polygon.reserve(std::max(polygon.capacity(), clip));
  clipped.reserve(std::max(clipped.capacity(), clip));
}

int manifold(const HullEdges& ha, const Vec3& xa, const Mat3& ra, const HullEdges& hb, const Vec3& xb,
             const Mat3& rb, ManifoldScratch& s, ManifoldPoint* out, int capacity, double margin) {
  const ConvexPolyhedron& a = *ha.hull;
  const ConvexPolyhedron& b = *hb.hull;
  s.world_a.clear();
  s.world_b.clear();
  for (const Vec3& v : a.vertices) s.world_a.push_back(xa + ra * v);
  for (const Vec3& v : b.vertices) s.world_b.push_back(xb + rb * v);

  // 1. Separating axes: faces of A, faces of B, then edge pairs.
  const FaceQuery fa = query_faces(a, xa, ra, s.world_b);
  if (fa.separation > margin) return 0;
  const FaceQuery fb = query_faces(b, xb, rb, s.world_a);
  if (fb.separation > margin) return 0;
  double edge_sep = -std::numeric_limits<double>::infinity();
  int edge_a = -1, edge_b = -1;
  Vec3 edge_axis = Vec3::Zero();
  for (int i = 0; i < static_cast<int>(ha.edges.size()); ++i) {
    const Vec3 da = s.world_a[ha.edges[i][1]] - s.world_a[ha.edges[i][0]];
    const bool faces_a = ha.edges[i][3] >= 0;
    const Vec3 ua = faces_a ? Vec3(ra * a.faces[ha.edges[i][2]].normal) : Vec3::Zero();
    const Vec3 va = faces_a ? Vec3(ra * a.faces[ha.edges[i][3]].normal) : Vec3::Zero();
    for (int j = 0; j < static_cast<int>(hb.edges.size()); ++j) {
      if (faces_a && hb.edges[j][3] >= 0 &&
          !minkowski_face(ua, va, -(rb * b.faces[hb.edges[j][2]].normal), -(rb * b.faces[hb.edges[j][3]].normal)))
        continue;
      const Vec3 db = s.world_b[hb.edges[j][1]] - s.world_b[hb.edges[j][0]];
      Vec3 axis = da.cross(db);
      const double len = axis.norm();
      if (len <= 1e-9 * da.norm() * db.norm()) continue;   // parallel edges: a face axis covers it
      axis /= len;
      // Both orientations: B beyond A along the axis, or along its opposite.
      double max_a = -std::numeric_limits<double>::infinity(), min_a = -max_a;
      double max_b = max_a, min_b = min_a;
      for (const Vec3& v : s.world_a) { const double d = axis.dot(v); max_a = std::max(max_a, d); min_a = std::min(min_a, d); }
      for (const Vec3& v : s.world_b) { const double d = axis.dot(v); max_b = std::max(max_b, d); min_b = std::min(min_b, d); }
      double sep = min_b - max_a;
      if (min_a - max_b > sep) {
        sep = min_a - max_b;
        axis = -axis;
      }
      if (sep > margin) return 0;
      if (sep > edge_sep) {
        edge_sep = sep;
        edge_a = i;
        edge_b = j;
        edge_axis = axis;
      }
    }
  }

  // 2. The reference face: A's unless B's is clearly less penetrating (Box2D's relative tolerance,
  // so that the choice seldom flickers on a resting stack; applied to how far the two separations
  // are apart, which works on either side of zero).
  constexpr double kRelative = 0.98;   // Box2D's k_relativeTol: hysteresis between choices
  constexpr double kAbsolute = 1e-6;   // m
  const auto clearly_beyond = [](double x) {   // m: what a separation must beat to be clearly less deep than x
    return (x <= 0.0 ? kRelative * x : (2.0 - kRelative) * x) + kAbsolute;
  };
  const bool flip = fb.separation > clearly_beyond(fa.separation);
  const Vec3 n_ref = flip ? Vec3(rb * b.faces[fb.face].normal) : Vec3(ra * a.faces[fa.face].normal);

  // 3. An edge-edge contact when its axis is clearly the least penetrating one and not nearly the
  // reference face's normal: two faces nearly parallel (a box landing tilted on another, its edge
  // crossing the other's edge) touch over their overlap, and one edge point there would let the
  // body pivot into the faces, whose points would not be in the manifold at all.
  const double face_sep = std::max(fa.separation, fb.separation);
  constexpr double kFaceAlignment = 0.9689124217106447;   // cos(0.25 rad): nearer than 14 degrees
  if (edge_a >= 0 && edge_sep > clearly_beyond(face_sep) && std::abs(edge_axis.dot(n_ref)) < kFaceAlignment) {
    Vec3 cp, cq;
    if (edge_closest(s.world_a[ha.edges[edge_a][0]], s.world_a[ha.edges[edge_a][1]],
                     s.world_b[hb.edges[edge_b][0]], s.world_b[hb.edges[edge_b][1]], cp, cq)) {
      if (capacity < 1) return 0;
      out[0].point = 0.5 * (cp + cq);
      out[0].normal = edge_axis;
      out[0].depth = -edge_sep;
      out[0].key = combine(combine(3, static_cast<std::uint64_t>(edge_a)), static_cast<std::uint64_t>(edge_b));
      return 1;
    }
  }

  // 4. Face contact: the reference face's side planes clip the incident face.
  const ConvexPolyhedron& ref = flip ? b : a;
  const ConvexPolyhedron& inc = flip ? a : b;
  const std::vector<Vec3>& wref = flip ? s.world_b : s.world_a;
  const std::vector<Vec3>& winc = flip ? s.world_a : s.world_b;
  const Mat3& rref = flip ? rb : ra;
  const Mat3& rinc = flip ? ra : rb;
  const int ref_face = flip ? fb.face : fa.face;
  const PolyFace& rf = ref.faces[ref_face];
  const Vec3 n = rref * rf.normal;   // out of the reference body
  // The incident face: the one most anti-parallel to the reference normal.
  int inc_face = 0;
  double lowest = std::numeric_limits<double>::infinity();
  for (int f = 0; f < static_cast<int>(inc.faces.size()); ++f) {
    const double d = (rinc * inc.faces[f].normal).dot(n);
    if (d < lowest) {
      lowest = d;
      inc_face = f;
    }
  }
  // Keys by the features of A and B that meet (point_key), never by which one is the reference:
  // a resting box whose two faces are about as deep as each other changes reference as it rocks,
  // and must keep its friction anchors when it does.
  const std::uint64_t own_ref = flip ? 1 : 0, own_inc = flip ? 0 : 1;
  const std::uint64_t ref_face_feature = feature(own_ref, kFace, static_cast<std::uint64_t>(ref_face));
  const std::uint64_t inc_face_feature = feature(own_inc, kFace, static_cast<std::uint64_t>(inc_face));
  const std::vector<int>& iv = inc.faces[inc_face].vertices;
  s.polygon.clear();
  for (std::size_t i = 0; i < iv.size(); ++i) {
    const int v = iv[i], w = iv[(i + 1) % iv.size()];
    s.polygon.push_back({winc[v], point_key(own_inc, feature(own_inc, kVertex, static_cast<std::uint64_t>(v)), ref_face_feature),
                         edge_feature(own_inc, v, w)});
  }

  // Sutherland-Hodgman against each side plane of the reference face: the plane through edge
  // i (v_i -> v_i+1, counter-clockwise about n) with outward normal e x n; keep the inner side.
  // A crossing of the polygon's edge p -> q with side plane i is where that edge meets the
  // reference face's edge i: an incident edge there (two edges meet), or, when p -> q was cut
  // along side plane j before, the reference face's corner between edges j and i (its vertex in
  // the incident face). The polygon's edge after an exit crossing runs along plane i.
  const int m = static_cast<int>(rf.vertices.size());
  for (int i = 0; i < m && !s.polygon.empty(); ++i) {
    const int r0 = rf.vertices[i], r1 = rf.vertices[(i + 1) % m];
    const Vec3& p0 = wref[r0];
    const Vec3 side = (wref[r1] - p0).cross(n);
    const std::uint64_t ref_edge = edge_feature(own_ref, r0, r1);
    const std::uint64_t plane = feature(own_ref, kSidePlane, static_cast<std::uint64_t>(i));
    s.clipped.clear();
    const int count = static_cast<int>(s.polygon.size());
    for (int k = 0; k < count; ++k) {
      const ManifoldScratch::ClipVertex& p = s.polygon[k];
      const ManifoldScratch::ClipVertex& q = s.polygon[(k + 1) % count];
      const double dp = side.dot(p.x - p0), dq = side.dot(q.x - p0);
      if (dp <= 0.0) s.clipped.push_back(p);
      if ((dp <= 0.0) != (dq <= 0.0)) {   // the edge p -> q crosses the plane: add the crossing
        const double t = dp / (dp - dq);
        std::uint64_t key = point_key(own_inc, p.edge, ref_edge);
        for (int j = 0; j < m; ++j) {   // p -> q lies along side plane j: the corner of j and i
          if (p.edge != feature(own_ref, kSidePlane, static_cast<std::uint64_t>(j))) continue;
          const int shared = j == (i + m - 1) % m ? r0 : (j == (i + 1) % m ? r1 : -1);
          key = shared >= 0 ? point_key(own_ref, feature(own_ref, kVertex, static_cast<std::uint64_t>(shared)), inc_face_feature)
                            : combine(combine(6, p.edge), plane);   // not a corner: clipped later
          break;
        }
        s.clipped.push_back({p.x + t * (q.x - p.x), key, dp <= 0.0 ? plane : p.edge});
      }
    }
    std::swap(s.polygon, s.clipped);
  }

  // Keep the points below the reference plane, at the middle of the overlap.
  const double plane = n.dot(wref[rf.vertices[0]]);
  int found = 0;
  for (const ManifoldScratch::ClipVertex& p : s.polygon) {
    const double depth = plane - n.dot(p.x);
    if (depth <= -margin) continue;
    ManifoldPoint point;
    point.point = p.x + 0.5 * depth * n;
    point.normal = flip ? Vec3(-n) : n;
    point.depth = depth;
    point.key = p.key;
    if (found < capacity) {
      out[found++] = point;
      continue;
    }
    // Full: replace the shallowest point kept if this one is deeper (ties: lower key kept).
    int shallowest = 0;
    for (int k = 1; k < capacity; ++k) {
      if (out[k].depth < out[shallowest].depth ||
          (out[k].depth == out[shallowest].depth && out[k].key > out[shallowest].key))
        shallowest = k;
    }
    if (point.depth > out[shallowest].depth) out[shallowest] = point;
  }
  return found;
}

}  // namespace graspsim

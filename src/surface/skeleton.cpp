// CGAL's mean-curvature-flow skeletonization (Tagliasacchi et al. 2012) per edge component.
//
// The only translation unit that includes CGAL: CGAL is header-only and slow to compile, so it is
// kept out of every other file (see skeleton.h for the interface).
//
// The flow needs a closed, manifold, connected triangle mesh. Each edge component (faces joined by
// paired edges, which are manifold and consistently oriented by construction of the topology) is
// copied into a CGAL Surface_mesh; each hole is closed with a fan of triangles around the hole's
// centroid (a long hole with rings of fewer vertices first: fill_with_rings), so open meshes
// (scans, disks like camelhead) get a skeleton of their closed-up shape, and a vertex of very many
// neighbours is replaced by such rings around its position (replace_hubs).
// A component that still is not a manifold surface (a pinched vertex), one with fewer than 4
// faces, or one where the flow throws is skipped: its faces keep the PCA field. A component of more
// than kFlowEdges edges is simplified first (the flow's cost is that of its first step on the
// whole mesh).
#include "surface/skeleton.h"

#include <CGAL/Mean_curvature_flow_skeletonization.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/shape_predicates.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Count_stop_predicate.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>
#include <CGAL/boost/graph/Euler_operations.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <stdexcept>
#include <vector>

namespace tailor::internal::skeleton_types {
using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
using Skeletonization = CGAL::Mean_curvature_flow_skeletonization<SurfaceMesh>;
using SkeletonGraph = Skeletonization::Skeleton;
using FlowEdge = boost::graph_traits<Skeletonization::Meso_skeleton>::edge_descriptor;
}  // namespace tailor::internal::skeleton_types

// The flow collapses short edges in the order of a std::set of its internal mesh's edges, which
// CGAL orders by memory address: the skeleton then changed from run to run (12 to 102 edges on
// the horse). Ordered by the halfedge ids instead (the flow renumbers them before every
// collapse pass, so they are unique there), the skeleton is the same on every run.
template <>
struct std::less<tailor::internal::skeleton_types::FlowEdge> {
  bool operator()(const tailor::internal::skeleton_types::FlowEdge& a,
                  const tailor::internal::skeleton_types::FlowEdge& b) const {
    return key(a) < key(b);
  }
  static std::size_t key(const tailor::internal::skeleton_types::FlowEdge& e) {
    return std::min(e.halfedge()->id(), e.halfedge()->opposite()->id());
  }
};

namespace tailor::internal {
namespace {

using namespace skeleton_types;

constexpr double kEdgeLengthFactor = 2.0;  // times the flow's shortest edge in CGAL's defaults (see below)
constexpr size_t kFlowEdges = 300000;      // 200k faces; the horse (146k edges) goes in whole

// Whether a face of `mesh` has collinear or coincident corners (in doubles).
template <class Mesh>
bool has_degenerate_face(const Mesh& mesh) {
  for (const auto f : faces(mesh))
    if (CGAL::Polygon_mesh_processing::is_degenerate_triangle_face(f, mesh)) return true;
  return false;
}

// Skeletonization::contract_until_convergence, step by step (the same steps, areas and stopping
// rule), with one check before each step: the medial centering asks CGAL's inside test for every
// pole, and that test shoots random rays until one meets no edge or vertex of the mesh; on a mesh
// with degenerate faces (collinear or coincident corners: a scan snapped to a grid, or faces the
// contraction flattened) none ever does and the flow never ends. From such a step on the flow
// contracts without the centering.
void contract_until_convergence(Skeletonization& flow) {
  const auto& meso = flow.meso_skeleton();
  const double original_area = CGAL::Polygon_mesh_processing::area(meso);
  double last_area = 0;
  for (size_t iteration = 0;;) {
    if (flow.is_medially_centered() && has_degenerate_face(meso)) flow.set_is_medially_centered(false);
    flow.contract();
    const double area = CGAL::Polygon_mesh_processing::area(meso);
    if (std::abs(last_area - area) / original_area < flow.area_variation_factor()) break;
    last_area = area;
    if (++iteration >= flow.max_iterations()) break;
  }
}

// A vertex of the flow's mesh with more neighbours than this is replaced by rings (fill_with_rings):
// the flow's linear solve fills in a dense block among a vertex's neighbours, so one of valence n
// costs n^2 memory (a disc of 8,000 faces around one vertex, or a hole of 8,000 edges closed
// with a fan: over 3 GB and a minute; 1,000: 73 MB, 0.5 s).
constexpr size_t kMaxFlowValence = 64;

using Halfedge = SurfaceMesh::Halfedge_index;
using Vertex = SurfaceMesh::Vertex_index;

// Closes the border cycle of h: while it has more than kMaxFlowValence vertices, with a ring of
// half as many (each on the mean of the two or three border vertices it joins, moved towards
// `centre` by about the border's mean edge, at most half way), then with a fan around `centre`.
// A ring vertex has 5 neighbours and at most 2 more from the ring inside it; a border vertex gains
// at most 2.
void fill_with_rings(SurfaceMesh& sm, Halfedge h, const Point& centre) {
  std::vector<Vertex> ring, inner;
  for (Halfedge g = h;;) {
    ring.push_back(sm.source(g));
    g = sm.next(g);
    if (g == h) break;
  }
  const auto towards = [&](double x, double y, double z, double step) {
    const double dx = x - centre.x(), dy = y - centre.y(), dz = z - centre.z();
    const double d = std::sqrt(dx * dx + dy * dy + dz * dz);
    const double keep = d > 0 ? std::max(0.5, 1.0 - step / d) : 0.0;
    return Point(centre.x() + keep * dx, centre.y() + keep * dy, centre.z() + keep * dz);
  };
  while (ring.size() > kMaxFlowValence) {
    const size_t n = ring.size(), m = (n + 1) / 2;
    double perimeter = 0;
    for (size_t i = 0; i < n; ++i)
      perimeter += std::sqrt(CGAL::squared_distance(sm.point(ring[i]), sm.point(ring[(i + 1) % n])));
    const double step = perimeter / static_cast<double>(n);
    inner.clear();
    for (size_t j = 0; j < m; ++j) {  // w_j joins the border edges 2j and 2j + 1 (the last may have one)
      double sum[3] = {0, 0, 0}, count = 0;
      for (size_t i = 2 * j; i <= std::min(2 * j + 2, n); ++i) {
        const Point& p = sm.point(ring[i % n]);
        sum[0] += p.x(), sum[1] += p.y(), sum[2] += p.z();
        ++count;
      }
      inner.push_back(sm.add_vertex(towards(sum[0] / count, sum[1] / count, sum[2] / count, step)));
    }
    const auto add = [&sm](Vertex a, Vertex b, Vertex c) {
      if (sm.add_face(a, b, c) == SurfaceMesh::null_face()) throw std::runtime_error("hole not closed");
    };
    for (size_t j = 0; j < m; ++j) {
      for (size_t i = 2 * j; i < std::min(2 * j + 2, n); ++i) add(ring[i], ring[(i + 1) % n], inner[j]);
      add(inner[j], ring[std::min(2 * j + 2, n) % n], inner[(j + 1) % m]);  // to the next ring vertex
    }
    ring.swap(inner);
    h = sm.halfedge(ring[0], ring[1]);  // the new ring's border runs the same way
  }
  CGAL::Euler::fill_hole(h, sm);
  const Halfedge middle = CGAL::Euler::add_center_vertex(h, sm);
  sm.point(sm.target(middle)) = centre;
}

// Closes every border cycle of `sm` (fill_with_rings towards its centroid); returns the number
// closed.
uint32_t close_holes(SurfaceMesh& sm) {
  std::vector<Halfedge> borders;
  std::vector<uint8_t> seen(sm.number_of_halfedges(), 0);
  for (Halfedge h : sm.halfedges()) {
    if (!sm.is_border(h) || seen[h.idx()]) continue;
    borders.push_back(h);
    for (Halfedge g = h; !seen[g.idx()]; g = sm.next(g)) seen[g.idx()] = 1;
  }
  for (Halfedge h : borders) {
    double sum[3] = {0, 0, 0};
    double n = 0;
    Halfedge g = h;
    do {
      const Point& p = sm.point(sm.target(g));
      sum[0] += p.x(), sum[1] += p.y(), sum[2] += p.z();
      ++n;
      g = sm.next(g);
    } while (g != h);
    fill_with_rings(sm, h, Point(sum[0] / n, sum[1] / n, sum[2] / n));
  }
  return static_cast<uint32_t>(borders.size());
}

// Replaces each vertex of more than kMaxFlowValence neighbours (a fan: a large polygon of the file
// triangulated around one corner, a cone's apex) by rings towards its own position.
void replace_hubs(SurfaceMesh& sm) {
  std::vector<Vertex> hubs;
  for (Vertex v : sm.vertices())  // interior: close_holes ran (remove_center_vertex needs a closed fan)
    if (sm.degree(v) > kMaxFlowValence && !sm.is_border(v)) hubs.push_back(v);
  for (Vertex v : hubs) {
    const Point at = sm.point(v);
    const Halfedge merged = CGAL::Euler::remove_center_vertex(sm.halfedge(v), sm);
    CGAL::Euler::remove_face(merged, sm);  // its halfedges are now the border of a hole
    fill_with_rings(sm, merged, at);
  }
  if (!hubs.empty()) sm.collect_garbage();
}

}  // namespace

Status compute_curve_skeleton(const Mesh& mesh, const Topology& topology, CurveSkeleton& skeleton) {
  const auto start = std::chrono::steady_clock::now();
  skeleton = CurveSkeleton{};
  const size_t face_count = mesh.face_count();
  if (topology.face_component.size() != face_count)
    return Status::error(ErrorCode::kInvalidMesh, "", "topology does not match the mesh");
  uint32_t components = 0;
  for (uint32_t c : topology.face_component) components = std::max(components, c + 1);
  skeleton.component_done.assign(components, 0);

  // Faces grouped by component (counting sort, face order kept within a component).
  std::vector<uint32_t> first(components + 1, 0), order(face_count);
  for (uint32_t c : topology.face_component) ++first[c + 1];
  for (uint32_t c = 0; c < components; ++c) first[c + 1] += first[c];
  {
    std::vector<uint32_t> fill(first.begin(), first.end() - 1);
    for (uint32_t f = 0; f < face_count; ++f) order[fill[topology.face_component[f]]++] = f;
  }

  std::vector<uint32_t> local(mesh.vertex_count(), kInvalid);
  for (uint32_t c = 0; c < components; ++c) {
    const uint32_t begin = first[c], end = first[c + 1];
    if (end - begin < 4) {
      ++skeleton.skipped_components;
      continue;
    }
    SurfaceMesh sm;
    std::vector<uint32_t> used;
    bool manifold = true;
    for (uint32_t i = begin; i < end && manifold; ++i) {
      SurfaceMesh::Vertex_index v[3];
      for (int k = 0; k < 3; ++k) {
        const uint32_t g = mesh.indices[3 * size_t{order[i]} + k];
        if (local[g] == kInvalid) {
          local[g] = static_cast<uint32_t>(used.size());
          used.push_back(g);
          const float* p = &mesh.positions[3 * size_t{g}];
          sm.add_vertex(Point(p[0], p[1], p[2]));
        }
        v[k] = SurfaceMesh::Vertex_index(local[g]);
      }
      manifold = sm.add_face(v[0], v[1], v[2]) != SurfaceMesh::null_face();
    }
    for (uint32_t g : used) local[g] = kInvalid;
    if (!manifold) {
      ++skeleton.skipped_components;
      continue;
    }
    uint32_t holes = 0;
    SkeletonGraph graph;
    try {
      holes = close_holes(sm);
      replace_hubs(sm);
      // The flow's first step runs on the whole mesh (168 s and 3.7 GB on a 1.55M-face horse):
      // above kFlowEdges, a simplified copy goes into the flow; the skeleton is coarse anyway.
      if (sm.number_of_edges() > kFlowEdges) {
        CGAL::Surface_mesh_simplification::Count_stop_predicate<SurfaceMesh> stop(kFlowEdges);
        CGAL::Surface_mesh_simplification::edge_collapse(sm, stop);
        sm.collect_garbage();
      }
      for (Vertex v : sm.vertices())
        skeleton.flow_max_valence = std::max(skeleton.flow_max_valence, static_cast<uint32_t>(sm.degree(v)));
      // The flow's Delaunay step shuffles points with CGAL's default generator, which is seeded
      // from the clock (and is per thread): a fixed seed per component makes the skeleton
      // the same on every run.
      CGAL::get_default_random() = CGAL::Random(1);
      Skeletonization flow(sm);
      // CGAL's default shortest edge (0.002 of the bounding-box diagonal) keeps the flow on
      // nearly the full mesh for many iterations: 33 s on the 97k-face horse (414 skeleton
      // edges). Twice that collapses short edges early: 3 s, 124 edges, every leg kept; four
      // times: 1.8 s but 19 edges (legs merged). CGAL's quality-speed trade-off is kept (0.1):
      // 0.05 halves the time but the horse's legs then get no skeleton of their own (the
      // skeleton test checks them).
      flow.set_min_edge_length(kEdgeLengthFactor * flow.min_edge_length());
      contract_until_convergence(flow);
      flow.convert_to_skeleton(graph);
    } catch (const std::exception&) {
      ++skeleton.skipped_components;
      continue;
    }
    // Copy out the graph; a skeleton without an edge or with a non-finite point is no use.
    const uint32_t base = static_cast<uint32_t>(skeleton.points.size() / 3);
    const size_t points_before = skeleton.points.size(), edges_before = skeleton.edges.size();
    bool finite = true;
    for (auto v : CGAL::make_range(vertices(graph))) {
      const Point& p = graph[v].point;
      finite = finite && std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z());
      skeleton.points.insert(skeleton.points.end(), {p.x(), p.y(), p.z()});
    }
    for (auto e : CGAL::make_range(edges(graph))) {
      skeleton.edges.push_back(base + static_cast<uint32_t>(source(e, graph)));
      skeleton.edges.push_back(base + static_cast<uint32_t>(target(e, graph)));
      skeleton.edge_component.push_back(c);
    }
    if (!finite || skeleton.edges.size() == edges_before) {
      skeleton.points.resize(points_before);
      skeleton.edges.resize(edges_before);
      skeleton.edge_component.resize(edges_before / 2);
      ++skeleton.skipped_components;
      continue;
    }
    skeleton.closed_holes += holes;
    skeleton.component_done[c] = 1;
  }
  skeleton.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return Status::ok();
}

}  // namespace tailor::internal

// tailor: face adjacency through opposite edges.
//
// Convention (used everywhere in tailor): edge e = 3f + k of face f runs from corner k to corner
// (k+1)%3, i.e. from vertex indices[3f+k] to indices[3f+(k+1)%3]. opposite[e] is the edge of the
// neighbouring face that runs the other way along the same two vertices, or kInvalid.
// The neighbour face is opposite[e] / 3 and its edge index within that face is opposite[e] % 3.
//
// Edges used by more than two faces (non-manifold) and pairs of faces that traverse a shared edge
// in the same direction (inconsistent orientation) are left unpaired, i.e. treated as boundary,
// and counted.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "tailor/api.h"
#include "tailor/mesh.h"
#include "tailor/progress.h"

namespace tailor {

struct Topology {
  std::vector<uint32_t> opposite;        //!< #F*3: opposite edge id or kInvalid
  std::vector<uint32_t> face_component;  //!< #F: component id through paired edges, numbered in order of lowest face
  uint32_t edge_components = 0;          //!< components through paired (manifold, consistent) edges
  uint32_t vertex_components = 0;        //!< components of faces sharing a vertex (what MANIFEST.md counts)
  size_t edges = 0;                      //!< distinct undirected edges
  size_t boundary_edges = 0;             //!< undirected edges used by exactly one face
  size_t nonmanifold_edges = 0;          //!< undirected edges used by three or more faces
  size_t inconsistent_edges = 0;         //!< undirected edges shared by two faces with the same direction
  double build_seconds = 0.0;
};

//! Builds the opposite-edge table and components. O(F) time: the edges grouped by their lower
//! vertex with a counting sort, then matched within each vertex's short list; no per-edge
//! allocation. Precondition: mesh passed finalize_mesh (indices < #V).
TAILOR_API Topology build_topology(const Mesh& mesh);

//! The same, telling `progress` (tailor/progress.h) the share done after each of its passes; it
//! cannot cancel (its return value is ignored).
TAILOR_API Topology build_topology(const Mesh& mesh, const ProgressCallback& progress);

//! The same on up to `threads` threads for the edge passes (0: one per core, from 250,000 faces
//! per thread, at most 8; 1: the calling thread only, as a caller that runs one mapping per core
//! wants). The result is the same for any count.
TAILOR_API Topology build_topology(const Mesh& mesh, const ProgressCallback& progress, uint32_t threads);

//! Vertices where the surface is not a manifold, as `tailor info` counts them: a vertex whose faces
//! do not form a single fan (faces joined through the edges at the vertex that exactly two faces
//! share, whichever way they run; a bow tie is two fans), or an end of an edge with three or more
//! faces. Vertices no face uses are not counted. O(F log valence) time, O(F) memory.
//! Precondition: as build_topology.
TAILOR_API size_t count_nonmanifold_vertices(const Mesh& mesh);

//! Turns the faces wound against their neighbours, so that every edge two faces share runs one
//! way in one face and the other way in the other: the topology's components (each runs one way)
//! that share an edge running the same way are joined, and in each group so joined the side of
//! the lesser area turns (its faces' corners 1 and 2 swap, with their UVs and attributes); on a
//! tie, the side whose least face (by its corners' positions) is the greater. Neither depends on
//! the order of the faces. A group whose sides meet both ways (a Moebius strip) keeps one of the
//! edges unpaired. Returns the number of faces turned (0 when `topology` is not the mesh's); the
//! topology no longer describes the mesh when it is not 0. O(F) time, plus a sort of the unpaired
//! edges.
TAILOR_API size_t orient_faces_coherently(Mesh& mesh, const Topology& topology);

//! The neighbour face across edge e, or kInvalid.
inline uint32_t neighbour_face(const Topology& t, uint32_t e) {
  const uint32_t o = t.opposite[e];
  return o == kInvalid ? kInvalid : o / 3;
}

}  // namespace tailor

// Faces wound against their neighbours: the edges they share running the same way.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "tailor/mesh.h"
#include "tailor/topology.h"

namespace tailor::internal {

//! The edges that exactly two faces share running the same way (the topology's inconsistent
//! edges, left unpaired): (edge of the lower face, edge of the other), in edge order. Only the
//! unpaired edges are sorted, so a mesh without them costs one pass.
std::vector<std::pair<size_t, size_t>> same_way_edge_pairs(const Mesh& mesh, const Topology& topology);

}  // namespace tailor::internal

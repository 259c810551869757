#pragma once
// Export of G_real for pictures and the report: JSON (the robot's node; nodes with id, position,
// state, frontier flags, cluster; edges with state, length, cost; clusters with centroids and
// viewpoints) and an ASCII PLY of nodes (coloured by state / frontier) and edges. Not for real-time
// paths.
#include <string>
#include <vector>

#include "core/graph/frontier_clusters.hpp"
#include "core/graph/reachable_graph.hpp"
#include "core/graph/viewpoint_generator.hpp"

namespace storey::core::graph {

const char* state_name(ElementState s);

std::string to_json(const ReachableGraph& g, const std::vector<FrontierCluster>* clusters = nullptr,
                    const std::vector<ClusterViewpoints>* viewpoints = nullptr);
// Colours: confirmed green, tentative blue, hypothetical grey; frontier nodes red.
std::string to_ply(const ReachableGraph& g);
// Writes `text` to `path`; false and `error` set (naming the path) on failure.
bool write_text_file(const std::string& path, const std::string& text, std::string* error);

}  // namespace storey::core::graph

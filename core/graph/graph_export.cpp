#include "core/graph/graph_export.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <unordered_map>

namespace storey::core::graph {

namespace {
void appendf(std::string& s, const char* fmt, auto... args) {
  char buf[256];
  const int n = std::snprintf(buf, sizeof(buf), fmt, args...);
  if (n > 0) s.append(buf, size_t(std::min(n, int(sizeof(buf)) - 1)));
}
}  // namespace

const char* state_name(ElementState s) {
  switch (s) {
    case ElementState::kConfirmed:
      return "confirmed";
    case ElementState::kTentative:
      return "tentative";
    case ElementState::kHypothetical:
      return "hypothetical";
  }
  return "unknown";
}

std::string to_json(const ReachableGraph& g, const std::vector<FrontierCluster>* clusters,
                    const std::vector<ClusterViewpoints>* viewpoints) {
  // The robot's node (-1: none): which component "reachable" is judged from.
  std::string s = "{\n\"root\": ";
  appendf(s, "%d,\n\"nodes\": [", g.root() == kNoId ? -1 : int(g.root()));
  bool first = true;
  for (NodeId i = 0; i < g.node_capacity(); ++i) {
    const GraphNode& n = g.node(i);
    if (!n.alive) continue;
    appendf(s,
            "%s\n {\"id\": %u, \"xyz\": [%.3f, %.3f, %.3f], \"state\": \"%s\", \"c_sur\": %s, "
            "\"c_exp\": %s, \"boundary\": %s, \"rho\": %.3f, \"open\": %d, \"floor\": %d, "
            "\"cluster\": %d, \"flight_lead\": %s}",
            first ? "" : ",", i, n.p_m.x(), n.p_m.y(), n.p_m.z(), state_name(n.state),
            n.c_sur ? "true" : "false", n.c_exp ? "true" : "false", n.boundary ? "true" : "false",
            n.rho, int(n.open_dirs), int(n.floor_hint), n.cluster,
            n.flight_lead ? "true" : "false");
    first = false;
  }
  s += "\n],\n\"edges\": [";
  first = true;
  for (EdgeId e = 0; e < g.edge_capacity(); ++e) {
    const GraphEdge& ge = g.edge(e);
    if (!ge.alive) continue;
    appendf(s,
            "%s\n {\"id\": %u, \"a\": %u, \"b\": %u, \"state\": \"%s\", \"length\": %.3f, "
            "\"cost\": %.3f}",
            first ? "" : ",", e, ge.a, ge.b, state_name(ge.state), ge.length_m, ge.cost);
    first = false;
  }
  s += "\n],\n\"clusters\": [";
  if (clusters) {
    first = true;
    for (const FrontierCluster& c : *clusters) {
      appendf(s, "%s\n {\"id\": %d, \"centroid\": [%.3f, %.3f, %.3f], \"nodes\": [",
              first ? "" : ",", c.id, c.centroid_m.x(), c.centroid_m.y(), c.centroid_m.z());
      for (size_t k = 0; k < c.nodes.size(); ++k) appendf(s, "%s%u", k ? ", " : "", c.nodes[k]);
      s += "], \"viewpoints\": [";
      if (viewpoints)
        for (const ClusterViewpoints& cv : *viewpoints)
          if (cv.cluster_id == c.id)
            for (size_t k = 0; k < cv.viewpoints.size(); ++k) {
              const Viewpoint& v = cv.viewpoints[k];
              appendf(s, "%s{\"node\": %u, \"yaw\": %.3f, \"visible\": %d}", k ? ", " : "", v.node,
                      v.yaw_rad, v.visible);
            }
      s += "]}";
      first = false;
    }
  }
  s += "\n]\n}\n";
  return s;
}

std::string to_ply(const ReachableGraph& g) {
  std::unordered_map<NodeId, uint32_t> index;
  std::string body;
  for (NodeId i = 0; i < g.node_capacity(); ++i) {
    const GraphNode& n = g.node(i);
    if (!n.alive) continue;
    const uint32_t idx = uint32_t(index.size());
    index[i] = idx;
    int r = 128, gr = 128, b = 128;
    if (n.frontier()) {
      r = 230, gr = 40, b = 40;
    } else if (n.state == ElementState::kConfirmed) {
      r = 40, gr = 200, b = 60;
    } else if (n.state == ElementState::kTentative) {
      r = 40, gr = 90, b = 230;
    }
    appendf(body, "%.3f %.3f %.3f %d %d %d\n", n.p_m.x(), n.p_m.y(), n.p_m.z(), r, gr, b);
  }
  size_t edges = 0;
  for (EdgeId e = 0; e < g.edge_capacity(); ++e) {
    const GraphEdge& ge = g.edge(e);
    if (!ge.alive) continue;
    const bool conf = ge.state == ElementState::kConfirmed;
    appendf(body, "%u %u %d %d %d\n", index.at(ge.a), index.at(ge.b), conf ? 40 : 40,
            conf ? 200 : 90, conf ? 60 : 230);
    ++edges;
  }
  std::string s = "ply\nformat ascii 1.0\ncomment storey reachable graph G_real\n";
  appendf(s, "element vertex %zu\n", index.size());
  s += "property float x\nproperty float y\nproperty float z\n"
       "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  appendf(s, "element edge %zu\n", edges);
  s += "property int vertex1\nproperty int vertex2\n"
       "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  return s + body;
}

bool write_text_file(const std::string& path, const std::string& text, std::string* error) {
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) {
    if (error) *error = "cannot open " + path + " for writing: " + std::strerror(errno);
    return false;
  }
  const bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  const bool closed = std::fclose(f) == 0;
  if (!(ok && closed)) {
    if (error) *error = "cannot write " + path + ": " + std::strerror(errno);
    return false;
  }
  return true;
}

}  // namespace storey::core::graph

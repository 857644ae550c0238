#pragma once

#include <optional>
#include <vector>

#include "dormant_tree_modeling/modeling/geometry_fit.h"
#include "dormant_tree_modeling/modeling/modeler_config.h"
#include "dormant_tree_modeling/modeling/point_index.h"

namespace dormant_tree_modeling {
namespace modeling {

/// @brief Clusters whose centroid lies at most this far (m) above the lowest cluster's are where
/// a trunk may start: Algorithm 2's start candidates and the trunk tracking's bases.
constexpr double TRUNK_BASE_BAND_M = 0.3;

/// @brief The widest cluster fit (m of radius) taken for a piece of trunk: a wider one is a
/// patch of ground, a wall or an arc of clutter.
constexpr double MAX_TRUNK_FIT_RADIUS_M = 0.3;

/// @brief A cluster of points (indices into the modeled cloud) and its cylinder fit.
struct Cluster {
  std::vector<int> members;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  std::optional<Cylinder> fit;  ///< least-squares cylinder; empty when the fit failed
  double error = 0.0;           ///< mean |d - r| of the fit (infinite without a fit)
};

/// @brief Whether a cluster may be a trunk's foot: its centroid at most TRUNK_BASE_BAND_M above
/// `zmin` (the lowest cluster's), at least 2 x min_cluster_points, and a cylinder fit within
/// trunk.max_tilt_deg of vertical. Algorithm 2's start candidates and the trunk tracking's bases.
bool isTrunkBase(const Cluster& cluster, double zmin, const ModelerConfig& config);

/// @brief Recompute centroid, cylinder fit and error of a cluster.
void updateCluster(const Points& pts, Cluster& cluster);

/// @brief Step 1: k-means into N_c = |pts| / cluster_points clusters (k-means++ seeding). With
/// config.noise.derive_parameters the points per cluster follow the density instead:
/// (0.15 m / spacing)^2, at most cluster_points.
/// @param spacing median nearest-neighbour distance of pts (m), 0 when unknown
std::vector<Cluster> initialClusters(const Points& pts, const ModelerConfig& config,
                                     double spacing = 0.0);

/// @brief e_t derived from the data: 1.5 x the 25th percentile of the clusters' fit errors
/// (clean cylinder pieces sit at the noise floor), never below the configured e_t.
double derivedSplitError(const std::vector<Cluster>& clusters, double configured);

/// @brief Step 2: split every cluster whose fit error exceeds e_t in two (2-means) until all
/// pass or reach 2 x min_cluster_points.
std::vector<Cluster> splitClusters(const Points& pts, std::vector<Cluster> clusters, double e_t,
                                   const ModelerConfig& config);

/// @brief Step 3: merge clusters whose centroids are closer than d_t, until none are.
std::vector<Cluster> mergeClusters(const Points& pts, std::vector<Cluster> clusters, double d_t);

/// @brief Step 4: adjacency lists of the bidirectional interface test: P_i and P_k are
/// connected when, from both sides, the point p nearest to the other cluster has between n_L
/// and n_H of its N nearest neighbours (in the whole cloud) in the other cluster.
/// @param index a PointIndex of `pts` (the whole cloud)
std::vector<std::vector<int>> connectClusters(const Points& pts, const PointIndex& index,
                                              const std::vector<Cluster>& clusters,
                                              const ModelerConfig& config);

/// @brief Result of step 5 and 6.
struct TrunkPath {
  std::vector<int> trunk;    ///< cluster indices, bottom to top
  std::vector<int> primary;  ///< clusters adjacent to the trunk that are not trunk
};

/// @brief Step 5: from the start cluster follow, at each step, the edge with the smallest angle
/// psi to the vertical while psi < psi_T (paper), starting at the lowest cluster. With
/// config.graph.follow_diameter the choice also weighs how well the next cluster's radius
/// continues the trunk's, and of the candidate bases near the bottom (sizeable, near-vertical
/// cylinder pieces) the one whose walk gathers the most clusters wins: a post has no branches.

/// Step 6: primary-branch clusters.
TrunkPath findTrunkPath(const std::vector<Cluster>& clusters,
                        const std::vector<std::vector<int>>& adjacency,
                        const ModelerConfig& config);

}  // namespace modeling
}  // namespace dormant_tree_modeling

#pragma once

#include <optional>
#include <vector>

#include "dormant_tree_modeling/common/cloud.h"
#include "dormant_tree_modeling/modeling/cluster_graph.h"
#include "dormant_tree_modeling/modeling/modeler_config.h"
#include "dormant_tree_modeling/modeling/point_index.h"
#include "dormant_tree_modeling/modeling/trunk_model.h"

namespace dormant_tree_modeling {
namespace modeling {

/// @brief One trunk base the modeler tracked (ours, graph.follow_diameter), for diagnostics.
struct TrunkCandidate {
  Eigen::Vector3d start = Eigen::Vector3d::Zero();  ///< where tracking began
  double start_radius = 0.0;       ///< the start's radius guess (m): its cluster's fitted radius
  bool from_column = false;        ///< a dense column of points, not a cluster, gave the start
  int slices = 0;                  ///< circles along the track (0: it did not take)
  double bottom = 0.0, top = 0.0;  ///< z range of the track (m)
  double median_radius = 0.0;      ///< of the track's circles (m)
  double score = -1.0;             ///< branch points around it, weighted
  /// its radius neither narrows upwards nor varies: a group more than half of whose voters
  /// read so is scored as a post
  bool pole = false;
  int group = -1;       ///< candidates whose tracks follow one trunk share a group
  bool chosen = false;  ///< the track that became the trunk's axis
  /// another upright column's track (a post, a neighbour's trunk): its surface is no branch
  bool other_column = false;
};

/// @brief Where a trunk track may begin.
struct TrunkStart {
  Eigen::Vector3d base = Eigen::Vector3d::Zero();    ///< lowest point of the start (m)
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  ///< the start's centre, reported (m)
  double radius = 0.0;                               ///< radius guess (m)
  bool from_column = false;                          ///< see TrunkCandidate::from_column
  int cluster = -1;                                  ///< the start's cluster, -1 for a column
  bool usable = true;  ///< false: Algorithm 2's trunk start without a cylinder fit
};

/// @brief Trunk starts from the clusters: Algorithm 2's trunk start first, then every sizeable
/// near-vertical cylinder fit in the lowest TRUNK_BASE_BAND_M of the clusters.
/// @param zmin the lowest cluster centroid's z (m)
std::vector<TrunkStart> clusterTrunkStarts(const std::vector<Cluster>& clusters,
                                           const TrunkPath& path, double zmin,
                                           const ModelerConfig& config);

/// @brief Trunk starts at the densest columns of points in the lowest TRUNK_BASE_BAND_M (above
/// `zmin`) that no start in `existing` stands within TRUNK_COLUMN_SEPARATION_M of: a trunk
/// whose lowest clusters are flat slabs (mixed pixels smear a scanner's returns behind a trunk
/// into wide, thin clusters, whose cylinder fits lie on their side) still stands as a column.
/// @param radius the starts' radius guess (m); the first circle of a track is free anyway
std::vector<TrunkStart> densityColumnStarts(const Points& pts, double zmin,
                                            const std::vector<TrunkStart>& existing, double radius,
                                            const ModelerConfig& config);

/// @brief Ours: track the leader from every plausible trunk base (the cluster starts and the
/// dense columns), group the tracks that stand on one base, and keep the trunk whose tracks
/// have the most points around them between 5 and 35 cm from their axis: branches. A post has
/// none, a neighbour's branch is no vertical cylinder.
/// @param report filled with one entry per start
/// @param columns if given, filled with the other upright columns the search tracked (a post,
///        a neighbour's trunk): each other group's representative whose track stands (climbs
///        half the clusters' height above its start) and keeps clear of the trunk's surface by
///        more than the tracking band at more than half of the heights they share, both ways (a
///        tree leaning on its post touches it over a part of its height)
std::optional<TrackedTrunk> trackBestTrunk(const Points& pts, const PointIndex& index,
                                           const std::vector<Cluster>& clusters,
                                           const TrunkPath& path, const ModelerConfig& config,
                                           std::vector<TrunkCandidate>* report,
                                           std::vector<TrackedTrunk>* columns = nullptr);

/// @brief Which points lie on an upright column: within its track's radius plus `band` (m) of
/// its axis, both read across the axis at the point's height (interpolated between the track's
/// circles), at heights the track spans. Such points are no branch of the tree: a post's
/// surface beside a tree came out as branch pieces. Points as near the trunk's surface are the
/// trunk's, where a column touches it.
/// @param trunk the trunk's track
/// @return one flag per point of `pts`
std::vector<char> pointsOnColumns(const Points& pts, const std::vector<TrackedTrunk>& columns,
                                  const TrackedTrunk& trunk, double band);

/// @brief The trunk's track measured again past other upright columns: from two circles below
/// the first that comes within `band` of a column's surface (their surfaces that near), climbed
/// again (climbAgainFrom) on the points off every column's surface (farther than `band` outside
/// it). A leader beside a post drifts onto the post's near side or ends where the post's arc
/// fills its slices. The new climb is kept when it reaches within a slice of the old one's top:
/// where a leader grows into its post, its points beside the post go with the post's, and the
/// climb ends early or turns onto a scaffold.
/// @param track the chosen trunk's track, bottom to top
/// @param columns other columns' tracks (trackBestTrunk's `columns`)
/// @param band the tracking band (m)
/// @return the new track, or `track` when no column comes that near or the climb is not kept
TrackedTrunk climbPastColumns(const Points& pts, TrackedTrunk track,
                              const std::vector<TrackedTrunk>& columns, double band,
                              const ModelerConfig& config);

/// @brief Cuts each track that ran onto another column below the circle where it joined it,
/// and empties one left with fewer than 3 circles. A track joins column b where its centre
/// first lies inside b's surface, when the two stood clear of each other (their surfaces apart)
/// at the lowest height both reach and the track, not b, moved across: its axis moved farther
/// from there than b's. Two columns standing apart at their feet do not become one; a trunk's
/// track whose radius a dense whorl widened wanders off and can end on a trellis post.
/// @param tracks one per start, empty where the start gave no track; cut in place, each
///        against the others as they were given
void cutWhereJoined(std::vector<std::optional<TrackedTrunk>>* tracks);

/// @brief Ends a post's track at the post's top. A track whose circles keep one radius over
/// its lower two thirds (median absolute deviation at most 2.5 % of their median, as a post's
/// do and a trunk's do not) is cut after its last circle where, over the 5 circles around it,
/// the median radius is within 15 % of that median or the centres' median offset from the line
/// through the lower two thirds' centres is at most half of it: a column of sections (a
/// calibration rig's pipe) narrows on its axis, a post's top does not. Where a leaning tree's
/// leader touches a post's top, the climb goes on onto the leader or around the crown, and the
/// track would take the tree's crown for the post's. Any other track is left as it is.
/// @param track cut in place
void endAtPostTop(TrackedTrunk* track);

/// @brief The trunk among tracked candidates. Tracks whose lowest BASE_HEIGHT stand on one base
/// are one trunk (a group); a group scores the median of its voters, the tracks that climb
/// most of its height (a track that stopped at a whorl has a small shell), halved when most of
/// them read as posts (neither narrowing upwards nor varying in radius: a post's tracks do
/// neither; one whose lower part a leaning tree touches may vary), and is represented
/// by the highest voter among those that stray alike from the others: a track that follows a
/// scaffold strays from the leader's, and one that stopped low is no judge of either.
/// @param tracks one per start, empty where the start gave no track
/// @param scores one per track (trackBestTrunk's shell score), -1 where there is none
/// @param zmin the lowest cluster centroid's z (m)
/// @param groups if given, filled with each track's group (-1 for none)
/// @return the chosen track's index, -1 when there is none
int chooseTrunkTrack(const std::vector<std::optional<TrackedTrunk>>& tracks,
                     const std::vector<double>& scores, double zmin,
                     std::vector<int>* groups = nullptr);

/// @brief Columns closer than this (m, horizontally) to a start are that start's trunk.
constexpr double TRUNK_COLUMN_SEPARATION_M = 0.15;

}  // namespace modeling
}  // namespace dormant_tree_modeling

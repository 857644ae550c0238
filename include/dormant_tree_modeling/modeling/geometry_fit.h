#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

namespace dormant_tree_modeling {
namespace modeling {

using Points = std::vector<Eigen::Vector3d>;
using Points2 = std::vector<Eigen::Vector2d>;

/// @brief A circle in a plane.
struct Circle {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  double radius = 0.0;
};

/// @brief A finite cylinder: axis through `center` along unit `axis`, radius, extent along
/// the axis of the points it was fitted to.
struct Cylinder {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  ///< middle of the axis segment
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  double radius = 0.0;
  double length = 0.0;
  double rms = 0.0;               ///< RMS of |distance to axis - radius| over the fitted points
  double mean_abs_error = 0.0;    ///< mean |distance to axis - radius|
  double mean_sq_distance = 0.0;  ///< mean squared distance to the axis (for the noise correction)
};

/// @brief Distance of p to the infinite axis of c.
double axisDistance(const Cylinder& c, const Eigen::Vector3d& p);

/// @brief Distance of p to the segment from a to b (to a when they coincide).
double segmentDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                       const Eigen::Vector3d& b);

/// @brief The angle (rad) between two lines along unit directions a and b, their signs
/// ignored: in [0, pi/2].
double lineAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b);

/// @brief Circle through three points; nothing when they are (nearly) collinear.
std::optional<Circle> circleThrough(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                                    const Eigen::Vector2d& c);

/// @brief Least-squares circle: algebraic (Kasa) start, then geometric Gauss-Newton.
/// @returns nothing for fewer than 3 points or a degenerate configuration
std::optional<Circle> fitCircle(const Points2& pts);

/// @brief Geometric circle fit from `start` that only the points near the circle pull: each
/// point is weighted by Tukey's biweight of its distance from the circle over `band`, and
/// points further out weigh nothing (iteratively reweighted Gauss-Newton). A branch leaving a
/// trunk, or anything else beside the circle, does not drag it the way it drags a plain fit
/// or a centroid.
/// @param start where the fit starts (centre and radius), e.g. the circle predicted from the
///        slices below
/// @param band half-width (m) of the band that holds the circle's points (noiseBand())
/// @returns nothing when fewer than 6 points lie within the band or the fit degenerates
std::optional<Circle> robustCircle(const Points2& pts, const Circle& start, double band);

/// @brief Options of ransacCircle().
struct CircleRansacConfig {
  double threshold = 0.005;  ///< m, inlier band around the circle
  int iterations = 200;
  double min_radius = 0.001;  ///< m
  double max_radius = 1.0;    ///< m
  /// m: the centre lies at most this far from the origin (a slice's centreline point)
  double max_center_offset = std::numeric_limits<double>::infinity();
  std::uint64_t seed = 1;
};

/// @brief RANSAC circle with radius bounds, refined on its inliers (within the bounds).
/// @param inliers set to the indices of the inliers of the result
std::optional<Circle> ransacCircle(const Points2& pts, const CircleRansacConfig& options,
                                   std::vector<int>* inliers = nullptr);

/// @brief The circle of a solid cross-section's surface when other things (branch bases,
/// shoots) add points outside it: the radius is the mode of the points' distances from the
/// centre (Gaussian kernel, bandwidth 0.6 sigma), the centre a least-squares fit with that
/// radius held over the points of the mode; alternated until both settle. A least-squares or
/// RANSAC circle with a band as wide as the noise drifts outwards onto such points.
/// @param start centre and radius to start from (a RANSAC circle)
/// @param sigma range noise (m): the kernel bandwidth and the band of the centre fit
/// @param min_radius, max_radius where the mode is searched (m)
/// @returns nothing for fewer than 3 points or empty bounds
std::optional<Circle> surfaceCircle(const Points2& pts, const Circle& start, double sigma,
                                    double min_radius, double max_radius);

/// @brief Geometric least-squares cylinder (Gauss-Newton on axis, centre and radius) from an
/// initial axis direction; the start comes from a circle fit in the plane orthogonal to it.
/// @param pts at least 6 points
/// @param axis_guess unit vector; its sign is kept in the result
/// @param fixed_axis keep the axis direction fixed (fit centre and radius only)
std::optional<Cylinder> fitCylinder(const Points& pts, const Eigen::Vector3d& axis_guess,
                                    bool fixed_axis = false);

/// @brief Principal direction (largest-variance eigenvector) and centroid of points.
Eigen::Vector3d principalAxis(const Points& pts, Eigen::Vector3d* centroid = nullptr,
                              Eigen::Vector3d* eigenvalues = nullptr);

/// @brief Options of ransacCylinder().
struct CylinderRansacConfig {
  double threshold = 0.01;  ///< m, inlier band |d - r|
  int circle_iterations = 150;
  int axis_candidates = 12;         ///< axis directions tried around the guess
  double max_axis_deviation = 0.5;  ///< rad, how far candidates may leave the guess
  double min_radius = 0.002;
  double max_radius = 0.5;
  std::uint64_t seed = 1;
};

/// @brief RANSAC cylinder for points without normals: axis candidates around a guess (the
/// guess, the principal axis when within the deviation bound, and seeded perturbations); for
/// each, a RANSAC circle in the orthogonal plane; the candidate with most inliers is refined
/// by fitCylinder() on its inliers. The radius stays within the bounds.
/// @param inliers set to indices of the final inliers
std::optional<Cylinder> ransacCylinder(const Points& pts, const Eigen::Vector3d& axis_guess,
                                       const CylinderRansacConfig& options,
                                       std::vector<int>* inliers = nullptr);

/// @brief Radius corrected for range noise: sqrt(mean d^2 - sigma^2) over the points closer
/// to the axis than radius + `band`, never below `min_radius`. A return's squared distance to
/// the axis is on average r^2 + sigma^2, so the plain fit estimates about sqrt(r^2 + sigma^2).

double noiseCorrectedRadius(const Cylinder& c, const Points& pts, double sigma, double band,
                            double min_radius);

/// @brief Cylinder for thin, noisy branches, where a RANSAC circle band would be wider than the
/// radius: a RANSAC line (band: max_radius + 2.5 sigma) refined by PCA on its inliers and moved
/// onto its slices' centroids (a slice whose centre lies farther off the line through the
/// others than the radius left out: a shoot or a secondary beside the branch), and the radius from
/// the scatter-corrected second moment sqrt(mean d^2 - scatter^2), d measured from the axis bent (a
/// parabola) through those centroids; a branch 2 sigmas thicker than the noise is centred on the
/// circle its cross-sections lie on instead (a one-sided view pulls the centroids towards the
/// scanner).
/// @param sigma range noise: sets the bands (m)
/// @param scatter total scatter removed from the moment (noise and beam spread), the median
///        over slices; 0: the raw RMS distance from the axis, a low quantile over slices with
///        the taper taken out (shoots and spurs left out), which may exceed max_radius by the
///        scatter (m)
/// @param inliers set to the indices of the points used for the radius
/// @param spread_radius set to the radius the points spread over, shoots and spurs included
///        (the median over slices; equal to the radius with a scatter to remove): what taking
///        the branch out of its cluster must take (m)
std::optional<Cylinder> fitThinCylinder(const Points& pts, const Eigen::Vector3d& axis_guess,
                                        double sigma, double scatter, double max_radius,
                                        std::uint64_t seed, std::vector<int>* inliers = nullptr,
                                        double* spread_radius = nullptr);

/// @brief Range noise from the radial residuals (d - r) of a circle or cylinder fit:
/// 1.4826 MAD x sqrt(3/2), because a return's radial residual carries on average 2/3 of its
/// range variance (incidence over a visible half-circle). 0 for no residuals.
double noiseFromRadialResiduals(std::vector<double> residuals);

/// @brief Deterministic k-means with k-means++ seeding from `seed`.
/// @param pts points
/// @param k clusters (clamped to the number of points)
/// @param max_iterations Lloyd iterations at most
/// @param seed seeding stream: equal inputs and seed give equal labels
/// @returns the cluster index of every point (every cluster non-empty)
std::vector<int> kMeans(const Points& pts, int k, int max_iterations, std::uint64_t seed);

}  // namespace modeling
}  // namespace dormant_tree_modeling

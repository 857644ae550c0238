#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "dormant_tree_modeling/common/parallel.h"
#include "dormant_tree_modeling/common/random.h"
#include "dormant_tree_modeling/common/statistics.h"
#include "dormant_tree_modeling/modeling/geometry_fit.h"
#include "dormant_tree_modeling/modeling/noise_band.h"

namespace dormant_tree_modeling {
namespace modeling {

namespace {

constexpr std::size_t PARALLEL_MIN_POINTS = 2000;  // below, one thread is faster

void basis(const Eigen::Vector3d& a, Eigen::Vector3d& u, Eigen::Vector3d& v) {
  u = a.unitOrthogonal();
  v = a.cross(u);
}

/// Fills length, centre (middle of the extent), and error statistics of c over pts.
void finish(Cylinder& c, const Points& pts) {
  double lo = 1e300, hi = -1e300, sq = 0.0, abs_err = 0.0, d2 = 0.0;
  for (const auto& p : pts) {
    const double t = (p - c.center).dot(c.axis);
    lo = std::min(lo, t);
    hi = std::max(hi, t);
    const double d = axisDistance(c, p);
    sq += (d - c.radius) * (d - c.radius);
    abs_err += std::abs(d - c.radius);
    d2 += d * d;
  }
  const double n = static_cast<double>(pts.size());
  c.center += 0.5 * (lo + hi) * c.axis;
  c.length = hi - lo;
  c.rms = std::sqrt(sq / n);
  c.mean_abs_error = abs_err / n;
  c.mean_sq_distance = d2 / n;
}

}  // namespace

double lineAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::min(1.0, std::abs(a.dot(b))));
}

double axisDistance(const Cylinder& c, const Eigen::Vector3d& p) {
  const Eigen::Vector3d w = p - c.center;
  return (w - w.dot(c.axis) * c.axis).norm();
}

double segmentDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                       const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double length2 = ab.squaredNorm();
  const double t = length2 > 0.0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

Eigen::Vector3d principalAxis(const Points& pts, Eigen::Vector3d* centroid,
                              Eigen::Vector3d* eigenvalues) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : pts)
    mean += p;
  mean /= static_cast<double>(std::max<std::size_t>(1, pts.size()));
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : pts)
    cov += (p - mean) * (p - mean).transpose();
  cov /= static_cast<double>(std::max<std::size_t>(1, pts.size()));
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
  if (centroid)
    *centroid = mean;
  if (eigenvalues)
    *eigenvalues = es.eigenvalues();
  return es.eigenvectors().col(2);
}

std::optional<Cylinder> fitCylinder(const Points& pts, const Eigen::Vector3d& axis_guess,
                                    bool fixed_axis) {
  if (pts.size() < 6)
    return std::nullopt;
  Eigen::Vector3d a = axis_guess.normalized();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : pts)
    mean += p;
  mean /= static_cast<double>(pts.size());
  Eigen::Vector3d u, v;
  basis(a, u, v);
  Points2 plane;
  plane.reserve(pts.size());
  for (const auto& p : pts)
    plane.emplace_back((p - mean).dot(u), (p - mean).dot(v));
  const auto circle = fitCircle(plane);
  if (!circle)
    return std::nullopt;
  Eigen::Vector3d c = mean + circle->center.x() * u + circle->center.y() * v;
  double r = circle->radius;
  if (!fixed_axis) {
    // Gauss-Newton on (centre shift in the plane, axis tilt, radius). On a cluster that is no
    // cylinder (a fork, a junction) the steps oscillate: the fit stops at the lowest cost seen
    // once a step fails to lower it.
    double previous_cost = std::numeric_limits<double>::infinity();
    Eigen::Vector3d previous_c = c, previous_a = a;
    double previous_r = r;
    for (int it = 0; it < 30; ++it) {
      basis(a, u, v);
      Eigen::Matrix<double, 5, 5> JtJ = Eigen::Matrix<double, 5, 5>::Zero();
      Eigen::Matrix<double, 5, 1> Jtr = Eigen::Matrix<double, 5, 1>::Zero();
      double cost = 0.0;
      for (const auto& p : pts) {
        const Eigen::Vector3d w = p - c;
        const double t = w.dot(a);
        const Eigen::Vector3d radial = w - t * a;
        const double d = radial.norm();
        if (d < 1e-12)
          continue;
        const Eigen::Vector3d n = radial / d;
        // Derivatives of the distance: centre shift along u, v; axis tilt towards u, v; radius.
        Eigen::Matrix<double, 5, 1> J;
        J << -n.dot(u), -n.dot(v), -t * n.dot(u), -t * n.dot(v), -1.0;
        JtJ.noalias() += J * J.transpose();  // fixed-size outer product: unrolled
        Jtr += J * (d - r);
        cost += (d - r) * (d - r);
      }
      if (!(cost < previous_cost * (1.0 - 1e-9))) {
        c = previous_c;
        a = previous_a;
        r = previous_r;
        break;
      }
      previous_cost = cost;
      previous_c = c;
      previous_a = a;
      previous_r = r;
      JtJ.diagonal() *= 1.0 + 1e-6;
      const Eigen::Matrix<double, 5, 1> step = JtJ.ldlt().solve(-Jtr);
      if (!step.allFinite())
        break;
      c += step(0) * u + step(1) * v;
      a = (a + step(2) * u + step(3) * v).normalized();
      r += step(4);
      if (step.norm() < 1e-8)
        break;
    }
  }
  if (!(r > 0.0) || !c.allFinite() || !a.allFinite())
    return std::nullopt;
  if (a.dot(axis_guess) < 0.0)
    a = -a;
  Cylinder cyl;
  cyl.axis = a;
  cyl.center = c + (mean - c).dot(a) * a;
  cyl.radius = r;
  finish(cyl, pts);
  return cyl;
}

std::optional<Cylinder> ransacCylinder(const Points& pts, const Eigen::Vector3d& axis_guess,
                                       const CylinderRansacConfig& o, std::vector<int>* inliers) {
  if (pts.size() < 6)
    return std::nullopt;
  Rng rng(o.seed);
  const Eigen::Vector3d guess = axis_guess.normalized();
  std::vector<Eigen::Vector3d> axes{guess};
  const Eigen::Vector3d pca = principalAxis(pts);
  const Eigen::Vector3d pca_signed = pca.dot(guess) < 0.0 ? Eigen::Vector3d(-pca) : pca;
  if (std::acos(std::min(1.0, pca_signed.dot(guess))) <= o.max_axis_deviation)
    axes.push_back(pca_signed);
  Eigen::Vector3d u, v;
  basis(guess, u, v);
  for (int i = 0; i < o.axis_candidates; ++i) {
    const double tilt = o.max_axis_deviation * std::sqrt(rng.uniform());
    const double az = rng.uniform(0.0, 2.0 * M_PI);
    axes.push_back((std::cos(tilt) * guess + std::sin(tilt) * (std::cos(az) * u + std::sin(az) * v))
                       .normalized());
  }
  CircleRansacConfig co;
  co.threshold = o.threshold;
  co.iterations = o.circle_iterations;
  co.min_radius = o.min_radius;
  co.max_radius = o.max_radius;
  // Each axis is tried independently (seeded by its index), on all cores; the best is
  // chosen in axis order, so the answer does not depend on the threads.
  std::vector<std::vector<int>> in(axes.size());
  std::vector<char> found(axes.size(), 0);
  parallelFor(
      static_cast<int>(axes.size()),
      [&](int k) {
        Eigen::Vector3d ku, kv;
        basis(axes[k], ku, kv);
        Points2 plane;
        plane.reserve(pts.size());
        for (const auto& p : pts)
          plane.emplace_back(p.dot(ku), p.dot(kv));
        CircleRansacConfig ko = co;
        ko.seed = o.seed * 1000003ULL + static_cast<std::uint64_t>(k);
        found[k] = ransacCircle(plane, ko, &in[k]).has_value();
      },
      pts.size() < PARALLEL_MIN_POINTS ? 1 : 0);
  std::vector<int> best_in;
  Eigen::Vector3d best_axis = guess;
  for (std::size_t k = 0; k < axes.size(); ++k) {
    if (found[k] && in[k].size() > best_in.size()) {
      best_in = std::move(in[k]);
      best_axis = axes[k];
    }
  }
  if (best_in.size() < 6)
    return std::nullopt;
  Points sub;
  for (const int i : best_in)
    sub.push_back(pts[i]);
  auto cyl = fitCylinder(sub, best_axis);
  // The refinement may leave the radius bounds or the axis cone: fall back to a fixed axis.
  if (!cyl || cyl->radius < o.min_radius || cyl->radius > o.max_radius ||
      lineAngle(cyl->axis, guess) > o.max_axis_deviation) {
    cyl = fitCylinder(sub, best_axis, true);
  }
  if (!cyl || cyl->radius < o.min_radius || cyl->radius > o.max_radius)
    return std::nullopt;
  if (inliers) {
    inliers->clear();
    for (std::size_t i = 0; i < pts.size(); ++i) {
      if (std::abs(axisDistance(*cyl, pts[i]) - cyl->radius) < o.threshold)
        inliers->push_back(static_cast<int>(i));
    }
  }
  return cyl;
}

double noiseFromRadialResiduals(std::vector<double> residuals) {
  if (residuals.empty())
    return 0.0;
  const double centre = median(residuals);
  for (double& r : residuals)
    r = std::abs(r - centre);
  return sigmaFromAbsoluteDeviations(std::move(residuals)) * std::sqrt(1.5);
}

double noiseCorrectedRadius(const Cylinder& c, const Points& pts, double sigma, double band,
                            double min_radius) {
  double sum = 0.0;
  int n = 0;
  for (const auto& p : pts) {
    // One-sided: every point inside the fitted surface counts, so the band is not centred on a
    // radius the noise already inflated.
    const double d = axisDistance(c, p);
    if (d < c.radius + band) {
      sum += d * d;
      ++n;
    }
  }
  if (n == 0)
    return c.radius;
  const double r2 = sum / n - sigma * sigma;
  return std::max(min_radius, std::sqrt(std::max(0.0, r2)));
}

}  // namespace modeling
}  // namespace dormant_tree_modeling

namespace dormant_tree_modeling {
namespace modeling {

namespace {

constexpr int MIN_THIN_POINTS = 6;
constexpr double MIN_THIN_RADIUS_M = 0.002;
// Robust re-centring works on slices of this length (m) along the axis.
constexpr double THIN_SLICE_M = 0.04;
// A parabola through the slice centres needs three; a fourth keeps it from passing through
// every centre's own scatter.
constexpr std::size_t MIN_BENT_SLICES = 4;
// A branch this many noise sigmas thick shows its arc: its centre comes from a circle fit to
// its cross-sections, which a one-sided view does not pull, if that circle's radius is within
// this factor of the moment's.
constexpr double ARC_MIN_SIGMAS = 2.0;
constexpr double ARC_RADIUS_SHARE = 2.0;
// A circle through one slice's points wants more of them than a centroid does.
constexpr int MIN_ARC_POINTS = 2 * MIN_THIN_POINTS;
// With at least this many slices the axis leaves out the first and the last: they are cut
// across by what bounds the part (the trunk's bark at a branch's base, the part's far end),
// so their centres are the least sure and, at the ends of the line, weigh the most.
constexpr std::size_t MIN_SLICES_WITHOUT_ENDS = 5;
// From this many centres on, the one farthest off the line through the others may be left out
// (dropStraySlice): three still fix the line.
constexpr std::size_t MIN_SLICES_FOR_STRAY = 4;
// A raw radius is this quantile of the slices' moments, taper taken out: shoots and spurs on a
// branch add to the moments of the slices they cross and never take from any, so a median
// reads a branch with shoots thicker than the rig's bare rods it is calibrated on. The tables
// map the quantile of clean slices as they mapped the median.
constexpr double SLICE_MOMENT_QUANTILE = 0.3;
// The taper is a slope fitted to at least this many slices; fewer keep their moments.
constexpr std::size_t MIN_TAPER_SLICES = 4;
// Rounds of re-centring and re-measuring a thin cylinder's points.
constexpr int THIN_FIT_ROUNDS = 5;

/// Whether a circle fitted to a branch's cross-sections is its surface: a radius within
/// ARC_RADIUS_SHARE of the moment's `radius` and a centre within that radius of where it was
/// sought.
bool plausibleArc(const std::optional<Circle>& circle, double radius) {
  return circle && circle->radius > radius / ARC_RADIUS_SHARE &&
         circle->radius < radius * ARC_RADIUS_SHARE && circle->center.norm() < radius;
}

/// The points within `band` of the line through o along d, into *out (its storage reused:
/// RANSAC calls this a hundred times a fit).
void nearLine(const Points& pts, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double band,
              std::vector<int>* out) {
  out->clear();
  for (int i = 0; i < static_cast<int>(pts.size()); ++i) {
    const Eigen::Vector3d w = pts[i] - o;
    if ((w - w.dot(d) * d).squaredNorm() < band * band)
      out->push_back(i);
  }
}

/// A line within 60 degrees of the guess holding the most points within `band` (100 RANSAC
/// samples, then two least-squares refits on its points); its points, and origin and direction
/// (towards the guess) in *cyl.
std::vector<int> thinAxis(const Points& pts, const Eigen::Vector3d& axis_guess, double band,
                          std::uint64_t seed, Cylinder* cyl) {
  const int n = static_cast<int>(pts.size());
  Rng rng(seed);
  Eigen::Vector3d origin = Eigen::Vector3d::Zero(), dir = axis_guess.normalized();
  principalAxis(pts, &origin);
  std::vector<int> best, in;
  nearLine(pts, origin, dir, band, &best);
  for (int it = 0; it < 100; ++it) {
    const Eigen::Vector3d& a = pts[rng.uniformInt(0, n - 1)];
    const Eigen::Vector3d& b = pts[rng.uniformInt(0, n - 1)];
    Eigen::Vector3d d = b - a;
    if (d.norm() < 4.0 * band)
      continue;
    d.normalize();
    if (std::abs(d.dot(axis_guess.normalized())) < std::cos(M_PI / 3.0))
      continue;
    nearLine(pts, a, d, band, &in);
    if (in.size() > best.size()) {
      best.swap(in);
      origin = a;
      dir = d;
    }
  }
  for (int round = 0; round < 2 && best.size() >= MIN_THIN_POINTS; ++round) {
    Points sub;
    for (const int i : best)
      sub.push_back(pts[i]);
    const Eigen::Vector3d d = principalAxis(sub, &origin);
    dir = d.dot(axis_guess) < 0.0 ? Eigen::Vector3d(-d) : d;
    nearLine(pts, origin, dir, band, &best);
  }
  cyl->center = origin;
  cyl->axis = dir;
  return best;
}

long thinSlice(const Cylinder& cyl, const Eigen::Vector3d& p) {
  return static_cast<long>(std::floor((p - cyl.center).dot(cyl.axis) / THIN_SLICE_M));
}

/// The centre of one slice's points (`slice` indexes pts; u and v span the plane across the
/// axis). A centroid lies on whatever part of the section was seen or kept (the side facing
/// the scanner, the near side the reach left, bark at a branch's base): a branch thick enough
/// to show its arc (arc_radius > 0) is centred on the circle its points lie on when that
/// circle is plausible and the slice holds MIN_ARC_POINTS; otherwise the centre is the centroid.
Eigen::Vector3d sliceCentre(const Points& pts, const std::vector<int>& slice,
                            const Eigen::Vector3d& u, const Eigen::Vector3d& v, double arc_radius) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const int i : slice)
    centroid += pts[i];
  centroid /= static_cast<double>(slice.size());
  if (arc_radius <= 0.0 || static_cast<int>(slice.size()) < MIN_ARC_POINTS)
    return centroid;
  Points2 section;
  for (const int i : slice)
    section.emplace_back((pts[i] - centroid).dot(u), (pts[i] - centroid).dot(v));
  const auto circle = fitCircle(section);
  if (!plausibleArc(circle, arc_radius))
    return centroid;
  return centroid + circle->center.x() * u + circle->center.y() * v;
}

/// Leaves out the slice centre farthest from the line through the other centres when it lies
/// farther from it than `radius`: that slice's points are mostly outside the branch, so it is
/// not the branch's cross-section but a side shoot, a secondary at a fork, or one beside the
/// end of a piece that a crossing branch's extraction cut off. With few slices one such centre
/// turns the line through all of them by 10-15 degrees, off the branch. A branch's own centres
/// stray by its bend and their noise, millimetres.
void dropStraySlice(Points& centres, double radius) {
  if (centres.size() < MIN_SLICES_FOR_STRAY)
    return;
  double worst = 0.0;
  std::size_t stray = 0;
  Points others;
  others.reserve(centres.size() - 1);
  for (std::size_t k = 0; k < centres.size(); ++k) {
    others.clear();
    for (std::size_t j = 0; j < centres.size(); ++j) {
      if (j != k)
        others.push_back(centres[j]);
    }
    Cylinder line;
    line.axis = principalAxis(others, &line.center);
    const double off = axisDistance(line, centres[k]);
    if (off > worst) {
      worst = off;
      stray = k;
    }
  }
  if (worst > radius)
    centres.erase(centres.begin() + static_cast<std::ptrdiff_t>(stray));
}

/// The points of `best` within `reach` of the axis (empty below MIN_THIN_POINTS), and the axis
/// moved onto the line through their slices' centres (sliceCentre; a full cross-section's
/// centroid is its centre; dropStraySlice with the current `radius`) when that stays within 30
/// degrees.
std::vector<int> recentre(const Points& pts, const std::vector<int>& best,
                          const Eigen::Vector3d& axis_guess, double reach, double radius,
                          double arc_radius, Cylinder* cyl) {
  std::vector<int> used;
  std::map<long, std::vector<int>> slices;
  for (const int i : best) {
    if (axisDistance(*cyl, pts[i]) >= reach)
      continue;
    used.push_back(i);
    slices[thinSlice(*cyl, pts[i])].push_back(i);
  }
  if (used.size() < MIN_THIN_POINTS)
    return {};
  Eigen::Vector3d u, v;
  basis(cyl->axis, u, v);
  Points centres;
  for (const auto& kv : slices) {
    if (kv.second.size() >= 3)
      centres.push_back(sliceCentre(pts, kv.second, u, v, arc_radius));
  }
  if (centres.size() >= MIN_SLICES_WITHOUT_ENDS)
    centres = Points(centres.begin() + 1, centres.end() - 1);
  dropStraySlice(centres, radius);
  if (centres.size() >= 2) {
    Eigen::Vector3d c;
    Eigen::Vector3d d = principalAxis(centres, &c);
    if (d.dot(axis_guess) < 0.0)
      d = -d;
    if (d.dot(cyl->axis) > std::cos(30.0 * M_PI / 180.0)) {
      cyl->center = c;
      cyl->axis = d;
    }
  }
  return used;
}

/// A branch's axis as a parabola along the fitted line: the offset across it as a quadratic
/// in the position along it, fitted to the slices' centres (sliceCentre). A branch bends by a few
/// degrees per slice; over a fit's length the straight line leaves its centre by millimetres, which
/// a radius from second moments would take for thickness.
class BentAxis {
 public:
  BentAxis(const Points& pts, const std::vector<int>& used, const Cylinder& cyl, double arc_radius)
      : centre_(cyl.center), axis_(cyl.axis) {
    basis(axis_, u_, v_);
    std::map<long, std::vector<int>> slices;
    for (const int i : used)
      slices[thinSlice(cyl, pts[i])].push_back(i);
    std::vector<Eigen::Vector3d> centres;
    for (const auto& kv : slices) {
      if (static_cast<int>(kv.second.size()) < MIN_THIN_POINTS)
        continue;
      const Eigen::Vector3d w = sliceCentre(pts, kv.second, u_, v_, arc_radius) - centre_;
      centres.emplace_back(w.dot(axis_), w.dot(u_), w.dot(v_));
    }
    if (centres.size() < MIN_BENT_SLICES)
      return;
    Eigen::MatrixXd a(centres.size(), 3);
    Eigen::MatrixXd b(centres.size(), 2);
    for (std::size_t k = 0; k < centres.size(); ++k) {
      const double t = centres[k].x();
      a.row(k) << 1.0, t, t * t;
      b.row(k) << centres[k].y(), centres[k].z();
    }
    coef_ = a.colPivHouseholderQr().solve(b);
  }
  /// The distance of p from the bent axis (from the straight one with too few slices).
  double distance(const Eigen::Vector3d& p) const { return across(p).norm(); }

  /// Moves the axis onto the centre of the circle the points' cross-sections (bend taken out)
  /// lie on, when that circle's radius is within ARC_RADIUS_SHARE of `radius`. A thick branch
  /// seen from one side has its slice centroids on that side: a moment about them reads it thin.
  void centreOnArc(const Points& pts, const std::vector<int>& used, double radius) {
    Points2 section;
    for (const int i : used)
      section.push_back(across(pts[i]));
    const auto circle = fitCircle(section);
    if (plausibleArc(circle, radius))
      shift_ = circle->center;
  }

 private:
  /// p's offset across the axis from it, in the (u, v) plane.
  Eigen::Vector2d across(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d w = p - centre_;
    const double t = w.dot(axis_);
    const Eigen::Vector3d basis(1.0, t, t * t);
    const Eigen::Vector2d off = coef_.transpose() * basis + shift_;
    return Eigen::Vector2d(w.dot(u_), w.dot(v_)) - off;
  }

  // The straight axis the bend is measured from, by value: the fit moves its cylinder on.
  Eigen::Vector3d centre_, axis_, u_, v_;
  Eigen::Matrix<double, 3, 2> coef_ = Eigen::Matrix<double, 3, 2>::Zero();
  Eigen::Vector2d shift_ = Eigen::Vector2d::Zero();
};

/// One slice's moment: the mean squared distance from the axis of its points within reach.
struct SliceMoment {
  double position;  ///< the slice's index along the axis
  double moment;    ///< m^2
};

/// The slices' moments taken to the middle of their run along a linear taper of their RMS
/// radii. The slope is Theil-Sen's (the median of the pairwise slopes), which the few slices a
/// shoot crosses do not tilt.
void removeTaper(std::vector<SliceMoment>& slices) {
  if (slices.size() < MIN_TAPER_SLICES)
    return;
  std::vector<double> slopes;
  for (std::size_t a = 0; a < slices.size(); ++a) {
    for (std::size_t b = a + 1; b < slices.size(); ++b) {
      slopes.push_back((std::sqrt(slices[b].moment) - std::sqrt(slices[a].moment)) /
                       (slices[b].position - slices[a].position));
    }
  }
  const double slope = median(std::move(slopes));
  const double middle = 0.5 * (slices.front().position + slices.back().position);
  for (auto& sl : slices) {
    const double rms = std::max(0.0, std::sqrt(sl.moment) - slope * (sl.position - middle));
    sl.moment = rms * rms;
  }
}

/// A branch's slices (of at least MIN_THIN_POINTS points within reach), and the mean of all
/// its squared distances within reach for when no slice has enough.
struct BranchSlices {
  std::vector<SliceMoment> slices;
  double pooled = 0.0;  ///< m^2
};

/// The moments of the slices of the squared distances from the axis within `reach`; nullopt
/// with fewer than MIN_THIN_POINTS. Without a scatter to remove (a raw moment, for a table or a
/// calibration to map) each slice's farthest fifth is left out: spurs and shoots on the branch.
std::optional<BranchSlices> sliceMoments(const Points& pts, const std::vector<int>& used,
                                         const Cylinder& cyl, const BentAxis& bent, double reach,
                                         bool raw) {
  std::map<long, std::vector<double>> sq_by_slice;
  for (const int i : used) {
    const double dist = bent.distance(pts[i]);
    if (dist < reach)
      sq_by_slice[thinSlice(cyl, pts[i])].push_back(dist * dist);
  }
  BranchSlices out;
  double total = 0.0;
  int total_n = 0;
  for (auto& [index, v] : sq_by_slice) {
    std::size_t keep = v.size();
    if (raw && v.size() >= 5) {
      keep = (v.size() * 4 + 4) / 5;
      std::nth_element(v.begin(), v.begin() + (keep - 1), v.end());
    }
    double sum = 0.0;
    for (std::size_t k = 0; k < keep; ++k)
      sum += v[k];
    total += sum;
    total_n += static_cast<int>(keep);
    if (static_cast<int>(keep) >= MIN_THIN_POINTS)
      out.slices.push_back({static_cast<double>(index), sum / keep});
  }
  if (total_n < MIN_THIN_POINTS)
    return std::nullopt;
  out.pooled = total / total_n;
  return out;
}

/// The moment the branch's points spread over, shoots and spurs included: the median over its
/// slices. It sets the fit's reach, and so its points.
double spreadMoment(const BranchSlices& b) {
  if (b.slices.empty())
    return b.pooled;
  std::vector<double> moments;
  for (const auto& sl : b.slices)
    moments.push_back(sl.moment);
  return median(std::move(moments));
}

/// The moment the branch's wood reads, for a table or a calibration to map: shoots and spurs
/// are left out of it by taking SLICE_MOMENT_QUANTILE of the slices' moments with the taper
/// removed. The tables absorb what that takes from the scatter.
double woodMoment(BranchSlices b) {
  if (b.slices.empty())
    return b.pooled;
  removeTaper(b.slices);
  std::vector<double> moments;
  for (const auto& sl : b.slices)
    moments.push_back(sl.moment);
  return quantileInPlace(moments, SLICE_MOMENT_QUANTILE);
}

/// Centre and length from the used points' extent along the axis, and their mean |d - r|.
void finishThinCylinder(const Points& pts, const std::vector<int>& used, Cylinder* cyl) {
  double lo = 1e300, hi = -1e300, abs_err = 0.0;
  for (const int i : used) {
    const double t = (pts[i] - cyl->center).dot(cyl->axis);
    lo = std::min(lo, t);
    hi = std::max(hi, t);
    abs_err += std::abs(axisDistance(*cyl, pts[i]) - cyl->radius);
  }
  cyl->center += 0.5 * (lo + hi) * cyl->axis;
  cyl->length = hi - lo;
  cyl->mean_abs_error = abs_err / static_cast<int>(used.size());
}

}  // namespace

std::optional<Cylinder> fitThinCylinder(const Points& pts, const Eigen::Vector3d& axis_guess,
                                        double sigma, double scatter, double max_radius,
                                        std::uint64_t seed, std::vector<int>* inliers,
                                        double* spread_radius) {
  if (pts.size() < MIN_THIN_POINTS)
    return std::nullopt;
  const double band = max_radius + std::max(noiseBand(sigma), 0.004);
  Cylinder cyl;
  const std::vector<int> best = thinAxis(pts, axis_guess, band, seed, &cyl);
  if (best.size() < MIN_THIN_POINTS)
    return std::nullopt;
  // Robust re-centring: per slice the centre of the points within radius + 2.5 sigma of the
  // current axis (sliceCentre), a line through those centres, the radius from the slices'
  // second moments about the axis bent through them (sliceMoments), less the scatter. A
  // parallel shoot or a spur moves a least-squares cylinder, not this. The points and the
  // centre follow the moments' spread, as the shoots belong to the branch taken out.
  std::vector<int> used;
  double radius = max_radius, wood_radius = max_radius;
  const bool raw = scatter <= 0.0;
  // Without a scatter to remove, the raw RMS distance is wanted (a calibration maps it): it
  // may exceed the radius bound by the scatter it carries.
  const double upper = raw ? max_radius + noiseBand(std::max(sigma, 0.004)) + 0.002 : max_radius;
  const auto toRadius = [&](double moment) {
    return std::clamp(std::sqrt(std::max(0.0, moment - scatter * scatter)), MIN_THIN_RADIUS_M,
                      upper);
  };
  for (int round = 0; round < THIN_FIT_ROUNDS; ++round) {
    // The moment must see the whole scatter it then subtracts.
    const double reach = radius + noiseBand(std::max(sigma, scatter)) + 0.002;
    // A raw radius still carries the noise. The first round's radius is only the bound.
    const double noiseless =
        raw ? std::sqrt(std::max(0.0, radius * radius - sigma * sigma)) : radius;
    const bool arc = round > 0 && noiseless >= ARC_MIN_SIGMAS * std::max(sigma, scatter);
    const double arc_radius = arc ? radius : 0.0;
    used = recentre(pts, best, axis_guess, reach, radius, arc_radius, &cyl);
    if (used.empty())
      return std::nullopt;
    BentAxis bent(pts, used, cyl, arc_radius);
    if (arc)
      bent.centreOnArc(pts, used, radius);
    const auto slices = sliceMoments(pts, used, cyl, bent, reach, raw);
    if (!slices)
      return std::nullopt;
    radius = toRadius(spreadMoment(*slices));
    // The reported radius is the last round's; with a scatter to remove it is the spread.
    if (round + 1 == THIN_FIT_ROUNDS)
      wood_radius = raw ? toRadius(woodMoment(*slices)) : radius;
  }
  cyl.radius = radius;
  finishThinCylinder(pts, used, &cyl);
  cyl.radius = wood_radius;
  if (inliers)
    *inliers = used;
  if (spread_radius)
    *spread_radius = radius;
  return cyl;
}

}  // namespace modeling
}  // namespace dormant_tree_modeling

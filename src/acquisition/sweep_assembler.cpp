#include "dormant_tree_modeling/acquisition/sweep_assembler.h"

#include <algorithm>
#include <cmath>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace acquisition {

void StagePositionHistory::add(double stamp, double theta) {
  if (!samples_.empty() && stamp <= samples_.back().stamp)
    return;
  samples_.push_back({stamp, theta});
  while (samples_.size() > capacity_)
    samples_.pop_front();
}

std::optional<double> StagePositionHistory::at(double stamp) const {
  if (samples_.empty())
    return std::nullopt;
  if (stamp <= samples_.front().stamp) {
    if (samples_.front().stamp - stamp > max_gap_s_)
      return std::nullopt;
    return samples_.front().theta;
  }
  if (stamp >= samples_.back().stamp) {
    if (stamp - samples_.back().stamp > max_gap_s_)
      return std::nullopt;
    return samples_.back().theta;
  }
  const auto after = std::lower_bound(samples_.begin(), samples_.end(), stamp,
                                      [](const Sample& s, double t) { return s.stamp < t; });
  const auto before = after - 1;
  const double gap = after->stamp - before->stamp;
  if (gap > max_gap_s_)
    return std::nullopt;
  const double w = (stamp - before->stamp) / gap;
  return before->theta + w * (after->theta - before->theta);
}

// One pass over the sweep's lines that fills the image row by row (angle lookup, binning and
// the counts the caller reports are shared state of that pass).
RangeImage assembleRangeImage(const std::vector<SweepLine>& lines,
                              const StagePositionHistory& history, double theta_min,
                              double theta_max, std::size_t* dropped, double theta_step,
                              std::size_t* missing) {
  struct Row {
    double theta0, rate, centre;
    const SweepLine* line;
  };
  std::vector<Row> rows;
  std::size_t lost = 0;
  const SweepLine* first = lines.empty() ? nullptr : &lines.front();
  for (const auto& l : lines) {
    if (l.ranges.size() != first->ranges.size() || std::abs(l.phi0 - first->phi0) > 1e-9 ||
        std::abs(l.phi_step - first->phi_step) > 1e-9) {
      throw Error(ErrorCode::INVALID_ARGUMENT,
                  "scan lines of one sweep differ in beam count or angles (" +
                      std::to_string(l.ranges.size()) + " vs " +
                      std::to_string(first->ranges.size()) + " beams)");
    }
    const std::size_t n = l.ranges.size();
    if (n == 0)
      continue;
    const auto t0 = history.at(l.stamp);
    const auto t1 = history.at(l.stamp + l.time_increment * (n - 1));
    if (!t0 || !t1) {
      ++lost;
      continue;
    }
    const double rate = n > 1 ? (*t1 - *t0) / (n - 1) : 0.0;
    const double centre = *t0 + rate * 0.5 * (n - 1);
    if (centre < theta_min || centre >= theta_max)
      continue;
    rows.push_back({*t0, rate, centre, &l});
  }
  std::stable_sort(rows.begin(), rows.end(),
                   [](const Row& a, const Row& b) { return a.centre < b.centre; });
  if (missing)
    *missing = 0;
  if (theta_step > 0 && !rows.empty()) {
    // One row per nominal angle: the nearest line within half a step, else an empty row.
    const int n = static_cast<int>(std::ceil((theta_max - theta_min) / theta_step - 1e-9));
    std::vector<Row> grid;
    for (int k = 0; k < n; ++k) {
      const double nominal = theta_min + k * theta_step;
      const auto best = std::min_element(rows.begin(), rows.end(), [&](const Row& a, const Row& b) {
        return std::abs(a.centre - nominal) < std::abs(b.centre - nominal);
      });
      if (std::abs(best->centre - nominal) <= 0.5 * theta_step) {
        grid.push_back(*best);
      } else {
        grid.push_back({nominal, 0.0, nominal, nullptr});
        if (missing)
          ++*missing;
      }
    }
    rows = std::move(grid);
  }
  RangeImage image;
  if (rows.empty()) {
    if (dropped)
      *dropped = lost;
    return image;
  }
  image.resize(static_cast<int>(rows.size()), static_cast<int>(first->ranges.size()));
  image.phi0 = first->phi0;
  image.phi_step = first->phi_step;
  image.theta0 = rows.front().centre;
  image.theta_step =
      rows.size() > 1 ? (rows.back().centre - rows.front().centre) / (rows.size() - 1) : 0.0;
  const bool rssi = std::all_of(rows.begin(), rows.end(), [&](const Row& r) {
    return !r.line || r.line->intensities.size() == r.line->ranges.size();
  });
  if (rssi)
    image.rssi.assign(image.range.size(), 0);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    image.row_theta.push_back(rows[i].theta0);
    image.row_theta_rate.push_back(rows[i].rate);
    image.row_stamp.push_back(rows[i].line ? rows[i].line->stamp : 0.0);
    if (!rows[i].line)
      continue;  // a missing line: no returns
    const SweepLine& l = *rows[i].line;
    for (int j = 0; j < image.cols; ++j) {
      const float r = l.ranges[j];
      image.at(static_cast<int>(i), j) = std::isfinite(r) && r > 0.0f ? r : 0.0f;
      if (rssi) {
        image.rssi[i * image.cols + j] =
            static_cast<std::uint8_t>(std::clamp(l.intensities[j], 0.0f, 255.0f));
      }
    }
  }
  if (dropped)
    *dropped = lost;
  return image;
}

std::size_t removeFloatingPixels(RangeImage& image, double rho_t) {
  std::vector<char> remove(image.range.size(), 0);
  for (int i = 0; i < image.rows; ++i) {
    for (int j = 0; j < image.cols; ++j) {
      const float rho = image.at(i, j);
      if (!(rho > 0.0f))
        continue;
      double closest = INFINITY;
      for (int di = -1; di <= 1; ++di) {
        for (int dj = -1; dj <= 1; ++dj) {
          const int k = i + di, l = j + dj;
          if ((di == 0 && dj == 0) || k < 0 || l < 0 || k >= image.rows || l >= image.cols)
            continue;
          const float n = image.at(k, l);
          if (n > 0.0f)
            closest = std::min(closest, std::abs(static_cast<double>(rho) - n));
        }
      }
      if (closest > rho_t)
        remove[static_cast<std::size_t>(i) * image.cols + j] = 1;
    }
  }
  std::size_t removed = 0;
  for (std::size_t p = 0; p < remove.size(); ++p) {
    if (remove[p]) {
      image.range[p] = 0.0f;
      ++removed;
    }
  }
  return removed;
}

void smoothRanges(RangeImage& image, double rho_t, int iterations) {
  for (int it = 0; it < iterations; ++it) {
    std::vector<float> out = image.range;
    for (int i = 0; i < image.rows; ++i) {
      for (int j = 0; j < image.cols; ++j) {
        const float rho = image.at(i, j);
        if (!(rho > 0.0f))
          continue;
        double sum = 0.0;
        int n = 0;
        for (int k = std::max(0, i - 1); k <= std::min(image.rows - 1, i + 1); ++k) {
          for (int l = std::max(0, j - 1); l <= std::min(image.cols - 1, j + 1); ++l) {
            const float v = image.at(k, l);
            if (v > 0.0f && std::abs(v - rho) <= rho_t) {
              sum += v;
              ++n;
            }
          }
        }
        out[static_cast<std::size_t>(i) * image.cols + j] = static_cast<float>(sum / n);
      }
    }
    image.range = std::move(out);
  }
}

}  // namespace acquisition
}  // namespace dormant_tree_modeling

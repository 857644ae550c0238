#!/usr/bin/env bash
# The core library (src/<area>, include/dormant_tree_modeling/<area>) must stay ROS-free so
# every algorithm is testable with plain gtest and reusable without a ROS master.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
bad=$(git ls-files -co --exclude-standard -- 'src/*' 'include/*' |
  grep -Ev '^(src/ros|src/nodes|include/dormant_tree_modeling/ros)/' |
  grep -E '\.(cpp|h)$' |
  xargs -r grep -lE '#include\s*[<"](ros/|roscpp|sensor_msgs/|std_msgs/|geometry_msgs/|tf2_ros/|pcl_conversions/|dormant_tree_modeling/(Cylinder|TreeModel|BranchMeasurement|MoveAxis)\.h)' || true)
if [[ -n "$bad" ]]; then
  echo "check_layering: ROS includes in the ROS-free core:" >&2
  echo "$bad" >&2
  exit 1
fi
echo "check_layering: core is ROS-free"

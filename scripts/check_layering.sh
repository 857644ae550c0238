#!/usr/bin/env bash
# Enforces the dependency graph of the code areas (docs/architecture.md, "Code areas"):
# - the core areas (src/<area>, include/dormant_tree_modeling/<area>) include no ROS header, so
#   every algorithm is testable with plain gtest and reusable without a ROS master;
# - an area includes only its own headers and those of the areas cmake/core.cmake declares for
#   it (DTM_AREA_DEPS_<area>), the same table that links the area libraries;
# - the ROS layer's real nodes include neither the emulators nor the simulation;
# - the graph drawn in docs/architecture.md is the declared one.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
failures=0
fail() {
  echo "check_layering: $*" >&2
  failures=$((failures + 1))
}

# Area -> space-separated dependencies, from the set(DTM_AREA_DEPS_<area> ...) calls.
declare -A deps
while IFS='|' read -r area list; do
  deps[$area]="$list"
done < <(tr '\n' ' ' < cmake/core.cmake | grep -oE 'set\(DTM_AREA_DEPS_[a-z0-9_]+[^)]*\)' |
  sed -E 's/set\(DTM_AREA_DEPS_([a-z0-9_]+) *("")? *([^)]*)\)/\1|\3/; s/ +/ /g; s/ $//')
[[ ${#deps[@]} -gt 0 ]] || { echo "check_layering: no DTM_AREA_DEPS_ in cmake/core.cmake" >&2; exit 1; }

ros_include='#include\s*[<"](ros/|roscpp|sensor_msgs/|std_msgs/|geometry_msgs/|tf2_ros/|pcl_conversions/|dormant_tree_modeling/(Cylinder|TreeModel|BranchMeasurement|MoveAxis|MovePlatform)\.h)'
for dir in src/* include/dormant_tree_modeling/*; do
  area=$(basename "$dir")
  case "$area" in ros | nodes | tools) continue ;; esac
  [[ -d "$dir" ]] || continue
  if [[ -z ${deps[$area]+set} ]]; then
    fail "$dir: area '$area' has no DTM_AREA_DEPS_$area in cmake/core.cmake"
    continue
  fi
  allowed=" $area ${deps[$area]} "
  while IFS= read -r file; do
    if grep -qE "$ros_include" "$file"; then
      fail "$file: ROS include in the ROS-free core"
    fi
    while IFS= read -r used; do
      [[ "$allowed" == *" $used "* ]] || fail "$file: area '$area' includes '$used/', not among its dependencies (${deps[$area]:-none})"
    done < <(grep -oE '#include\s*"dormant_tree_modeling/[a-z0-9_]+/' "$file" |
      sed -E 's#.*dormant_tree_modeling/([a-z0-9_]+)/#\1#' | sort -u)
  done < <(git ls-files -co --exclude-standard -- "$dir" | grep -E '\.(cpp|h)$')
done

# The real nodes: everything in the ROS layer except the virtual platform's node.
while IFS= read -r file; do
  if grep -qE '#include\s*"dormant_tree_modeling/(emulation|simulation)/' "$file"; then
    fail "$file: a real node includes the emulators or the simulation"
  fi
done < <(git ls-files -co --exclude-standard -- src/ros src/nodes include/dormant_tree_modeling/ros |
  grep -E '\.(cpp|h)$' | grep -v 'virtual_platform_node')

# The drawn graph: every edge "a --> b" of docs/architecture.md's flowchart, common left out
# (every area may use it), against the declared one.
declared=$(for area in "${!deps[@]}"; do
  for d in ${deps[$area]}; do [[ "$d" == common ]] || echo "$area --> $d"; done
done | sort)
drawn=$(sed -n '/<!-- area-graph -->/,/```$/p' docs/architecture.md |
  grep -oE '^\s*[a-z0-9_]+ --> [a-z0-9_]+' | sed -E 's/^\s*//' | sort || true)
if [[ -z "$drawn" ]]; then
  fail "docs/architecture.md: no flowchart after <!-- area-graph -->"
elif [[ "$declared" != "$drawn" ]]; then
  fail "docs/architecture.md's area graph differs from cmake/core.cmake:"$'\n'"$(diff <(echo "$drawn") <(echo "$declared") | grep '^[<>]' | sed 's/^</  drawn only:/; s/^>/  declared only:/')"
fi

if [[ $failures -gt 0 ]]; then
  exit 1
fi
echo "check_layering: ${#deps[@]} areas, no ROS in the core, every include along a declared dependency"

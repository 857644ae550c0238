#!/usr/bin/env bash
# make demo: the whole ROS graph (launch/demo.launch) against the virtual platform scans one
# synthetic tree with the paper's 40-view plan, registers the views and models the tree; the
# results are gathered in results/<tree>/ and scored against the ground truth.
#   DEMO_PRESET (young_tall_spindle), DEMO_SEED (1), DEMO_NOISE_MM (6) choose the tree;
#   rviz opens when there is a display (DEMO_GUI=0: never); DEMO_TIMEOUT (900 s) bounds the run.
set -uo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="$root/.build/devel/lib/dormant_tree_modeling"
preset="${DEMO_PRESET:-young_tall_spindle}"
seed="${DEMO_SEED:-1}"
noise="${DEMO_NOISE_MM:-6}"
timeout_s="${DEMO_TIMEOUT:-900}"
tree="${preset}_seed${seed}"
out="$root/results/$tree"
run="$out/run"
gui=false
[[ "${DEMO_GUI:-1}" != 0 && -n "${DISPLAY:-}" ]] && gui=true
start=$(date +%s)
elapsed() { echo $(($(date +%s) - start)); }
say() { printf '[%4d s] %s\n' "$(elapsed)" "$*"; }

rm -rf "$run" && mkdir -p "$run"
# ROS's setup scripts read unset variables.
set +u
# shellcheck disable=SC1091
source "$root/.build/devel/setup.bash"
set -u
# A master of our own, on a free port, so the demo neither joins nor disturbs another graph.
port=""
for p in $(seq 11711 11760); do
  if ! (exec 3<>"/dev/tcp/127.0.0.1/$p") 2>/dev/null; then port=$p; break; fi
done
[[ -n "$port" ]] || { echo "demo: no free port for roscore" >&2; exit 1; }
export ROS_MASTER_URI="http://127.0.0.1:$port" ROS_HOME="$run/ros_home"
pids=()
stop_all() {
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do kill -INT "${pids[i]}" 2>/dev/null; done
  for pid in "${pids[@]}"; do
    for _ in $(seq 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null
  done
  pids=()
}
trap stop_all EXIT
roscore -p "$port" >"$run/roscore.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do rostopic list >/dev/null 2>&1 && break; sleep 0.2; done

say "the graph against the virtual platform: $preset seed $seed, ${noise} mm range noise, LMS111 at 50 Hz / 0.5 deg (log: $run/ros.log)"
roslaunch dormant_tree_modeling demo.launch preset:="$preset" seed:="$seed" noise_mm:="$noise" \
  tree_name:="$tree" output_dir:="$run" gui:="$gui" >"$run/ros.log" 2>&1 &
launch_pid=$!
pids+=($launch_pid)

# The latest value of a topic's field (topic/field), on one line.
progress() { timeout 5 rostopic echo -n1 -p "$1" 2>/dev/null | sed -n '2s/^[^,]*,//p'; }
last=""
model="$run/model/model.json"
while [[ ! -f "$model" ]]; do
  if ! kill -0 "$launch_pid" 2>/dev/null; then
    echo "demo: roslaunch stopped; the end of $run/ros.log:" >&2
    tail -20 "$run/ros.log" >&2
    exit 1
  fi
  if (($(elapsed) > timeout_s)); then
    echo "demo: no model after $timeout_s s; the last progress: $last (log: $run/ros.log)" >&2
    exit 1
  fi
  now="$(progress /acquisition/progress/text)"
  if [[ -n "$now" && "$now" != "$last" ]]; then
    say "acquisition: $now"
    last="$now"
  fi
  sleep 5
done
sleep 1  # the modeler writes model.json first, then the CSV and the clouds
reg_dir="$(ls -d "$run"/registration/*/ 2>/dev/null | tail -1)"
[[ -n "$reg_dir" ]] && say "registration: $(grep -m1 'views registered' "$reg_dir/registration.md")"
say "model written: $(grep -c '^primary_branch' "$run/model/cylinders.csv") primary branches"

picture_note="not taken (no Xvfb/rviz/ImageMagick)"
if "$root/scripts/rviz_screenshot" "$out/rviz.png" --wait 10 >"$run/rviz_screenshot.log" 2>&1; then
  picture_note="rviz.png"
  say "rviz screenshot: $out/rviz.png"
else
  say "rviz screenshot not taken: $(tail -1 "$run/rviz_screenshot.log")"
fi
stop_all

cp "$run/model/model.json" "$run/model/cylinders.csv" "$run/truth/truth.json" "$out/"
cp "$run/model/cloud.pcd" "$out/registered.pcd"
cp "$run/model/cloud.ply" "$out/registered.ply"
[[ -n "$reg_dir" ]] && cp "$reg_dir/registration.md" "$out/registration.md"
cp "$run/$tree"_report.md "$out/acquisition.md" 2>/dev/null
"$bin/render_model" "$out/registered.pcd" "$out/model.json" --output "$out/model.png"
score=$("$bin/evaluate_model" --model "$out/model.json" --truth "$out/truth.json")
details=$("$bin/evaluate_model" --model "$out/model.json" --truth "$out/truth.json" --details | head -60)
prune=$(awk -F, 'NR > 1 && $1 == "primary_branch" && $18 == 1' "$out/cylinders.csv" | wc -l)
branches=$(awk -F, 'NR > 1 && $1 == "primary_branch"' "$out/cylinders.csv" | wc -l)
total=$(elapsed)
{
  echo "# $tree"
  echo
  echo "Synthetic $preset (seed $seed), scanned on the virtual platform by the whole ROS graph"
  echo "(\`launch/demo.launch\`: lms111_driver, stage_controller, scan_assembler, acquisition,"
  echo "registration, tree_modeler) with the paper's 40-view plan, the LMS111 at 50 Hz / 0.5°"
  echo "with $noise mm range noise, the platform placed by a virtual operator up to 0.2 m / 8°"
  echo "off each planned position after the first. Registration automatic, no hand crop."
  echo "Run time: $total s. Frame: orchard (the tree's frame of the simulation)."
  echo
  echo "![the cylinders over the registered cloud (trunk brown, primary branches green, pruning candidates red)](model.png)"
  echo
  echo "## Against the ground truth (as the paper's Table 3)"
  echo
  echo '```'
  echo "$score"
  echo '```'
  echo
  echo "## Measurements"
  echo
  echo "$branches primary branches, $prune of them pruning candidates (diameter above half the"
  echo "trunk's); every cylinder with attachment height, angle to the trunk and diameter ratio in"
  echo "cylinders.csv."
  echo
  echo "<details><summary>Each detection against the truth</summary>"
  echo
  echo '```'
  echo "$details"
  echo '```'
  echo "</details>"
  echo
  echo "## Files"
  echo
  echo "registered.pcd / registered.ply (the registered tree, orchard frame), model.json,"
  echo "cylinders.csv, truth.json, model.png, rviz screenshot: $picture_note, registration.md"
  echo "(per view: pose, rmse, overlap, confidence), acquisition.md; the raw scans as a bag in"
  echo "run/$tree.bag (\`roslaunch dormant_tree_modeling replay.launch bag:=...\`)."
} >"$out/report.md"
echo
echo "$score"
echo
say "demo: done -> $out/report.md"

#!/usr/bin/env bash
# what each localisation buys on a scenario (the README's SLAM table, like
# the paper's Tables I and II): dead reckoning, FastSLAM 1.0, FastSLAM 2.0,
# FastSLAM 2.0 with the pose graph, the LiDAR-inertial odometry alone and
# under the graph, each a full run of the scenario (as many at once as the
# machine has cores; the update times then measure a loaded machine).
#   tools/slam_table.sh [SCENARIO.ini] [--set section.key=value]...
# Prints a Markdown table. Runs ./paddock (which builds first).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
scenario="${1:-$root/scenarios/fsg_2023_trackdrive.ini}"
[ $# -gt 0 ] && shift
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT

runs=(
  "odometry (dead reckoning)|--set autonomy.slam=odometry"
  "FastSLAM 1.0|--set autonomy.slam=fastslam --set slam.fastslam_version=1"
  "FastSLAM 2.0|--set autonomy.slam=fastslam --set slam.fastslam_version=2"
  "FastSLAM 2.0 + pose graph|--set autonomy.slam=fastslam_graph"
  "LIO|--set autonomy.slam=lio"
  "LIO + FastSLAM 2.0 + pose graph|--set autonomy.slam=lio_graph"
  "ground truth (reference)|--set autonomy.slam=ground_truth"
)

# build once, then the runs side by side
"$root/paddock" keys >/dev/null
jobs="$(nproc)"
for i in "${!runs[@]}"; do
  sets="${runs[$i]#*|}"
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do sleep 0.2; done
  # shellcheck disable=SC2086
  "$root/build/paddock" run "$scenario" $sets "$@" --quiet --out "$out/run$i" >/dev/null 2>"$out/err$i" &
done
wait

# one number of a flat key in summary.json's "slam" object (or the top level)
field() { grep -o "\"$2\":[^,}]*" "$1" | head -1 | cut -d: -f2; }

echo "| localisation | ATE rms [m] | ATE max [m] | heading rms [rad] | drift [m / 100 m] | map rmse [m] | precision | recall | colour | loop closures | LIO slices degenerate | update mean / p99 [ms] | total time [s] | DOO | OC |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for i in "${!runs[@]}"; do
  name="${runs[$i]%%|*}"
  s="$out/run$i/summary.json"
  if [ ! -f "$s" ]; then
    echo "| $name | run failed: $(head -c 200 "$out/err$i") |"
    continue
  fi
  # the slam object without its per-lap array (keys come in alphabetical order)
  grep -o '"slam":{.*' "$s" | sed 's/"laps":\[[^]]*\]//' > "$out/slam.txt"
  grep -o '"penalties":{[^}]*' "$s" > "$out/penalties.txt"
  slices="$(field "$out/slam.txt" lio_slices)"
  degenerate="-"
  [ "$slices" != "0" ] && degenerate="$(field "$out/slam.txt" lio_degenerate_slices) / $slices"
  printf '| %s | %.3f | %.3f | %.4f | %.3f | %.3f | %.3f | %.3f | %.3f | %s | %s | %.2f / %.2f | %.3f | %s | %s |\n' "$name" \
    "$(field "$out/slam.txt" ate_rms_m)" "$(field "$out/slam.txt" ate_max_m)" "$(field "$out/slam.txt" heading_rms_rad)" \
    "$(field "$out/slam.txt" drift_m_per_100m)" \
    "$(field "$out/slam.txt" map_rmse_m)" "$(field "$out/slam.txt" map_precision)" "$(field "$out/slam.txt" map_recall)" \
    "$(field "$out/slam.txt" map_colour_accuracy)" "$(field "$out/slam.txt" loop_closures)" "$degenerate" \
    "$(field "$out/slam.txt" update_ms_mean)" "$(field "$out/slam.txt" update_ms_p99)" \
    "$(field "$s" total_time)" "$(field "$out/penalties.txt" doo)" "$(field "$out/penalties.txt" oc)"
done

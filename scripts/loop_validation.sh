#!/usr/bin/env bash
# The loop's validation (issue 13, docs/loop.md): for each scenario, generate
# two training experiments and one held-out experiment of the paper's arm on
# the loop sample's short protocol (case 4, 0.2 mm marker noise, occlusions,
# each through the mocap pipeline at load), with effects the nominal
# configuration does not declare, run `ccsrm loop` on them, and tabulate what
# it found against the truth. About 10 minutes per scenario on 2 cores.
#
# Declared-value scenarios (issue 28): the arm as built differs from the
# configuration in one measured value; the recordings are generated from
# the arm as built, their markers processed with its layout (a lab's mocap
# knows where its markers are), and the loop runs under the declared
# configuration (--config).
#
# Usage: scripts/loop_validation.sh OUT_DIR [SCENARIO ...]
# Scenarios: null backlash mocap_offset table_tilt joint_friction
#            actuator_delay two outside (default: all), the declared
#            values: hole_radius hole_radius_s1 pulley_radius link_length
#            disk_gap disk_gap_2mm disk_gap_20deg, and terms found in
#            the data: cubic angle_friction input_drag
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:?usage: scripts/loop_validation.sh OUT_DIR [SCENARIO ...]}
shift
scenarios=("$@")
if [ ${#scenarios[@]} -eq 0 ]; then
  scenarios=(null backlash mocap_offset table_tilt joint_friction actuator_delay two outside)
fi
ccsrm=${CCSRM:-./build/app/ccsrm}
config=datasets/samples/loop/arm.yaml
mkdir -p "$out"

# The truth of each scenario: generator flags beyond the case.
flags() {
  case "$1" in
    null) echo "" ;;
    backlash) echo "--effect backlash" ;;
    mocap_offset) echo "--effect mocap_offset" ;;
    table_tilt) echo "--effect table_tilt:lateral_rad=0.02" ;;
    joint_friction) echo "--effect joint_friction:coulomb_nm=0.1,viscous_nmsprad=0.005" ;;
    actuator_delay) echo "--effect actuator_delay:time_constant_s=0.03,dead_time_s=0.02" ;;
    two) echo "--effect table_tilt:lateral_rad=0.02 --effect actuator_delay:time_constant_s=0.03,dead_time_s=0.02" ;;
    # None of the library's effects: the conduits' static friction is a
    # third above their kinetic friction (the configuration declares them
    # equal), and the loop does not fit it.
    outside) echo "--set mu_c_s=0.28" ;;
    # Terms found in the data (issue 28): a joint moment that is none of
    # the library's effects. A hardening spring in every joint, cubic in
    # its angle (0.23 N m at 6 deg), and a friction that grows with the
    # angle (0.16 N m at 6 deg; joint_friction's is constant).
    cubic) echo "--effect joint_moment:segment1_x_angle3=-200,segment2_x_angle3=-200" ;;
    angle_friction) echo "--effect joint_moment:segment1_x_abs_angle_sign_rate=-1.5,segment2_x_abs_angle_sign_rate=-1.5" ;;
    # A drag that follows the inputs' rate rather than the joint's (0.13 N m
    # at the ramps' peak commanded rate, 0.066 rad/s).
    input_drag) echo "--effect joint_moment:segment1_x_input_rate=-2,segment2_x_input_rate=-2" ;;
    hole_radius | hole_radius_s1 | pulley_radius | link_length | disk_gap*) echo "" ;;
    *) echo "unknown scenario $1" >&2; exit 2 ;;
  esac
}

# The arm as built of a declared-value scenario: the configuration with one
# value off (sed on its first occurrence from the given line on); empty for
# the others.
built() {
  case "$1" in
    # Segment 2's hole circle drilled 0.8 mm (5 %) small.
    hole_radius) sed '35s/hole_circle_radius_m: 0.016/hole_circle_radius_m: 0.0152/' "$config" ;;
    # Segment 1's hole circle drilled 0.5 mm (2.4 %) small.
    hole_radius_s1) sed '20s/hole_circle_radius_m: 0.021/hole_circle_radius_m: 0.0205/' "$config" ;;
    # Segment 1's large-S pulleys 5 % large.
    pulley_radius) sed '28s/pulley_radius_m: 0.016 /pulley_radius_m: 0.0168 /' "$config" ;;
    # Segment 2's links 1 mm (1 %) long.
    link_length) sed '32s/link_length_m: 0.100/link_length_m: 0.101/' "$config" ;;
    # The joint disks 0.5 mm (3 %) and 2 mm (12.5 %) further apart. The gap
    # enters the cable paths at second order in the angle (docs/loop.md):
    # 0.5 mm again with bends of 20 degrees (disk_gap_20deg).
    disk_gap) sed '11s/joint_disk_gap_m: 0.016/joint_disk_gap_m: 0.0165/' "$config" ;;
    disk_gap_2mm) sed '11s/joint_disk_gap_m: 0.016/joint_disk_gap_m: 0.018/' "$config" ;;
    disk_gap_20deg) built disk_gap ;;
    *) ;;
  esac
}

for s in "${scenarios[@]}"; do
  dir="$out/$s"
  mkdir -p "$dir"
  f=$(flags "$s")
  arm=$config
  suffix=""
  declared=()
  if [ -n "$(built "$s")" ]; then
    built "$s" >"$dir/built.yaml"
    cmp -s "$dir/built.yaml" "$config" && { echo "$s: the edit did not apply" >&2; exit 2; }
    arm=$dir/built.yaml
    suffix=_processed
    declared=(--config "$config")
  fi
  # Training at +6 and -4 degrees, held out at +5, different noise seeds;
  # the large-bend scenarios at +20, -15 and +18.
  a=(6 -4 5)
  case "$s" in *_20deg) a=(20 -15 18) ;; esac
  for spec in "train1 ${a[0]} 11" "train2 ${a[1]} 12" "holdout ${a[2]} 13"; do
    set -- $spec
    [ -f "$dir/$1$suffix.h5" ] && continue
    # shellcheck disable=SC2086
    $ccsrm generate --config "$arm" --case 4 --amplitude "$2" --seed "$3" $f --quiet \
      --out "$dir/$1.h5" >/dev/null
    if [ -n "$suffix" ]; then
      $ccsrm mocap process --in "$dir/$1.h5" --inputs "$dir/$1.h5" --config "$arm" --quiet \
        --out "$dir/$1$suffix.h5" >/dev/null
    fi
  done
  if [ ! -f "$dir/loop/loop.json" ]; then
    start=$(date +%s)
    $ccsrm loop --data "$dir/train1$suffix.h5" "$dir/train2$suffix.h5" \
      --holdout "$dir/holdout$suffix.h5" "${declared[@]}" \
      --free mu_c,T_p --out "$dir/loop" >"$dir/loop.log" 2>/dev/null || true
    echo "$s: $(($(date +%s) - start)) s"
  fi
done

/usr/bin/python3 - "$out" "${scenarios[@]}" <<'EOF'
import json, os, sys, yaml
out, scenarios = sys.argv[1], sys.argv[2:]
print("| data (undeclared truth) | first pick | added | parameters: fitted (truth) [95 % interval] | training RMS before → after [°] | held-out before → after [°] | floor [°] | sims, wall |")
print("|---|---|---|---|---|---|---|---|")
for s in scenarios:
    d = os.path.join(out, s)
    path = os.path.join(d, "loop", "loop.json")
    if not os.path.exists(path):
        print(f"| {s} | (no loop.json) |||||||")
        continue
    j = json.load(open(path))
    truth = yaml.safe_load(open(os.path.join(d, "train1.truth.yaml")))
    built_path = os.path.join(d, "built.yaml")
    effects = truth.get("effects") or {}
    declared = {"c_sc": 0.05, "c_lc": 0.05, "mu_c_s": 0.21}
    changed = {k: v for k, v in (truth.get("parameters") or {}).items()
               if k in declared and abs(v - declared[k]) > 1e-12}
    # An effect's parameters that are not 0 (the terms' carrier lists all 36).
    label = ", ".join(f"{e}({', '.join(f'{k}={v:g}' for k, v in (p or {}).items() if v != 0)})"
                      for e, p in effects.items()) or (
        ", ".join(f"{k}={v:g}" for k, v in changed.items()) or "none")
    if os.path.exists(built_path):
        declared_arm = open("datasets/samples/loop/arm.yaml").read().splitlines()
        edits = [f"{a.split('#')[0].strip()} → {b.split(':', 1)[1].split('#')[0].strip()}"
                 for a, b in zip(declared_arm, open(built_path).read().splitlines()) if a != b]
        label = "declared value: " + "; ".join(edits)
    first = j["rounds"][0]["candidates"][0]["name"] if j["rounds"] and j["rounds"][0]["candidates"] else "-"
    added = ", ".join(j["added_effects"]) or "none"
    parts_declared = []
    for c in j.get("declared_corrections", []):
        alt = f" (or {', '.join(c['indistinguishable'])})" if c["indistinguishable"] else ""
        added += f"; corrected {c['parameter']}{alt}"
        ci = c["relative_ci95"]
        ci_text = f"[{ci[0]:+.4f}, {ci[1]:+.4f}]" if ci[0] is not None else "[not identifiable]"
        parts_declared.append(f"{c['parameter']} {c['relative']:+.4f} {ci_text}")
    parts = []
    for name, p in j["parameters"].items():
        if "." not in name:
            continue
        eff, short = name.split(".", 1)
        t = (effects.get(eff) or {}).get(short)
        ci = p["ci95"]
        ci_text = f"[{ci[0]:.3g}, {ci[1]:.3g}]" if ci[0] is not None else "[not identifiable]"
        if eff in ("mocap_offset", "declared"):
            continue
        parts.append(f"{name} {p['value']:.3g} ({t if t is not None else 0:g}) {ci_text}")
    if "mocap_offset" in j["added_effects"]:
        ok = 0
        total = 0
        for name, p in j["parameters"].items():
            if not name.startswith("mocap_offset."):
                continue
            t = (effects.get("mocap_offset") or {}).get(name.split(".", 1)[1], 0.0)
            total += 1
            ci = p["ci95"]
            inside = ci[0] is not None and ci[0] <= t <= ci[1]
            close = t != 0 and abs(p["value"] - t) <= 0.2 * abs(t)
            ok += inside or close
        parts.append(f"mocap_offset: {ok}/{total} offsets within 20 % or inside their interval")
    parts = parts_declared + parts
    hb, ha = j["holdout_rms_before_deg"], j["holdout_rms_after_deg"]
    print(f"| {label} | {first} | {added} | {'; '.join(parts) or '-'} | "
          f"{j['rms_before_deg']:.4f} → {j['rms_after_deg']:.4f} | "
          f"{hb:.4f} → {ha:.4f} | {j['noise_floor_deg']:.4f} | {j['simulations']}, {j['wall_time_s']:.0f} s |")
EOF

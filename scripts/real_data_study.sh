#!/usr/bin/env bash
# The real-data study of docs/real_data.md: identification and sim-to-real diagnosis on the
# measured UTFSM records (data/utfsm/). Reruns everything into OUT (default runs/real_data):
#   1. actuator: chirp_0A cut in two halves; rths identify on the first half; rths diagnose
#      --train first --test second --model act.toml (and the reverse, and the paper's model);
#   2. MR damper, at 0, 0.5 and 1 A: rths identify --damper on the 25 mm tests at 0.1, 0.25 and
#      0.5 Hz, held-out scores on 10 mm / 1 Hz, 5 mm / 3 Hz, 2 mm / 5 Hz; rths diagnose with the
#      fitted model (one dt per diagnosis: 5 ms: train the 25 mm tests, test 2 mm / 5 Hz; 1 ms:
#      train 10 mm / 1 Hz, test 5 mm / 3 Hz), and with the paper's Table 3 damper at 1 A;
#      each 1 A test fitted alone;
#   3. the chirp's force with the first-half actuator and the 0 A damper model (diagnose both channels);
#   4. sinusoids to earthquakes (held out): the current-dependent damper model (no --current) fitted
#      on the sinusoid tests at all five currents (all 30, and the 1 kHz ones only; each also with
#      --skew auto --inertia auto), scored on the earthquake tests at 0.2 ... 1 A
#      (data/utfsm/mr_damper_earthquake/validacion.mat); the authors' moving average applied to
#      sinusoid tests; rths diagnose train 1 kHz sinusoids at one current, test the earthquake test
#      at the nearest current. The longest part: about 23 min on 2 cores (20 fits of 15 s to 3.4 min;
#      with --skew auto the all-30 fit stops at commit f91e132, and runs about 9 min a current).
# Usage: scripts/real_data_study.sh [OUT]     (binaries: build/bin, or set RTHS_BIN_DIR)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="${1:-$here/runs/real_data}"
rths="${RTHS:-$here/rths}"   # RTHS: another entry point (testing)
data="$here/data/utfsm"
mkdir -p "$out"
cd "$out"
log() { echo; echo "=== $*"; }

log "actuator: chirp_0A, two halves"
"$rths" utfsm-convert "$data/actuator/chirp_0A.txt" --out chirp_0A.csv
# 51.216 s: the first half [0, 25.608) s, the second [25.608, end) (tests/ident/identify_test.cpp's split).
"$rths" utfsm-convert chirp_0A.csv --to-s 25.608 --out chirp_first.csv
"$rths" utfsm-convert chirp_0A.csv --from-s 25.608 --out chirp_second.csv
"$rths" identify chirp_first.csv --out act_first.toml
"$rths" identify chirp_second.csv --out act_second.toml
rm -rf diag_chirp_first_second diag_chirp_second_first diag_chirp_paper
log "diagnose: train first half, test second half, model identified on the first half"
"$rths" diagnose --train chirp_first.csv --test chirp_second.csv --model act_first.toml --out diag_chirp_first_second
log "diagnose: train second half, test first half, model identified on the second half"
"$rths" diagnose --train chirp_second.csv --test chirp_first.csv --model act_second.toml --out diag_chirp_second_first
log "diagnose: the paper's nominal model (Eq. 30, Table 3) on the chirp halves"
"$rths" diagnose --train chirp_first.csv --test chirp_second.csv --out diag_chirp_paper

# Damper tests: u = y = x. The displacement channel is a copy of the command, so the model files
# give it a near-identity actuator (poles at 1 kHz: the ZOH leaves one sample of lag), and the
# constant current needs no current dynamics.
identity='actuator = { K = 248050213442.4, p = 6283.185307, b = 8885.765876, c = 39478417.6 }'
train_tests="25mm0x1Hz 25mm0x25Hz 25mm0x5Hz"
held_tests="10mm1Hz 5mm3Hz 2mm5Hz"
for cur in 0 0x5 1; do
  amps="${cur/x/.}"
  train=() held=()
  for t in $train_tests; do
    "$rths" utfsm-convert "$data/mr_damper/${t}${cur}A.txt" --out "${t}${cur}A.csv" > /dev/null
    train+=("${t}${cur}A.csv")
  done
  for t in $held_tests; do
    "$rths" utfsm-convert "$data/mr_damper/${t}${cur}A.txt" --out "${t}${cur}A.csv" > /dev/null
    held+=("${t}${cur}A.csv")
  done
  log "damper at $amps A: fit on ${train[*]}, held out ${held[*]}"
  "$rths" identify --damper "${train[@]}" --current "$amps" --check "${held[@]}" \
    --out "damper_${cur}A.toml" --plot "damper_${cur}A.png"
  { printf '# nominal model for damper-only tests at %s A (scripts/real_data_study.sh)\n[plant]\n' "$amps"
    printf 'current_dynamics = false\n%s\n\n' "$identity"
    cat "damper_${cur}A.toml"; } > "model_${cur}A.toml"
  # rths diagnose takes one dt per diagnosis: the 5 ms tests (25 mm, 2 mm / 5 Hz) and the 1 ms
  # tests (10 mm / 1 Hz, 5 mm / 3 Hz) are diagnosed apart, both with the model fitted above.
  rm -rf "diag_damper_${cur}A_5ms" "diag_damper_${cur}A_1ms"
  log "diagnose: damper at $amps A, fitted model, 5 ms records: train the 25 mm tests, test 2 mm / 5 Hz"
  "$rths" diagnose --train "${train[@]}" --test "2mm5Hz${cur}A.csv" --model "model_${cur}A.toml" \
    --out "diag_damper_${cur}A_5ms"
  log "diagnose: damper at $amps A, fitted model, 1 ms records: train 10 mm / 1 Hz, test 5 mm / 3 Hz"
  "$rths" diagnose --train "10mm1Hz${cur}A.csv" --test "5mm3Hz${cur}A.csv" --model "model_${cur}A.toml" \
    --out "diag_damper_${cur}A_1ms"
  if [[ "$cur" == 1 ]]; then
    { printf '# the paper Table 3 damper (200 kN) for the 1 A damper tests\n[plant]\n'
      printf 'specimen = "mr_damper"\ncurrent_dynamics = false\n%s\n' "$identity"; } > model_table3.toml
    rm -rf diag_damper_1A_5ms_table3
    log "diagnose: damper at 1 A, the paper's Table 3 damper, 5 ms records"
    "$rths" diagnose --train "${train[@]}" --test "2mm5Hz${cur}A.csv" --model model_table3.toml \
      --out diag_damper_1A_5ms_table3
  fi
done
# The chirp's force (0 A) with the actuator of the first half and the damper fitted at 0 A on the
# 25 mm tests: a held-out test of the damper model on another excitation (2 mm, up to 20 Hz).
grep -v '^\[controller\]\|^model = ' act_first.toml > act_damper_0A.toml
cat damper_0A.toml >> act_damper_0A.toml
log "damper at 0 A on the chirp's force (held out)"
"$rths" identify --damper 25mm0x1Hz0A.csv 25mm0x25Hz0A.csv 25mm0x5Hz0A.csv --current 0 \
  --check chirp_first.csv chirp_second.csv | grep -A3 "held-out"
rm -rf diag_chirp_force
log "diagnose: chirp halves with the identified actuator and the damper fitted at 0 A"
"$rths" diagnose --train chirp_first.csv --test chirp_second.csv --model act_damper_0A.toml --out diag_chirp_force

log "damper at 1 A, each test fitted alone (the pre-yield travel against the stroke)"
for t in $train_tests $held_tests; do
  "$rths" identify --damper "${t}1A.csv" --current 1 | grep -E "pre-yield|^    .*%$"
done

# 4. Sinusoids to earthquakes (held out). validacion.mat holds one variable, data (64648 x 6): column
# 1 x [mm], columns 2-6 the force F [N] at 0.2, 0.4, 0.6, 0.8, 1.0 A; 1 kHz, no time column
# (data/README.md). A column map names one force column and its current (i=VALUE), and one map
# applies to every mapped file, so each current is its own rths identify (the same fit each time).
# With --columns the UTFSM damper .txt files are not read by their own format: all 30 are converted
# to rig records first (those of section 2 again, the same bytes), which are read as they are.
eq="$data/mr_damper_earthquake/validacion.mat"
eq_amps=(0.2 0.4 0.6 0.8 1.0)            # data(:,2) ... data(:,6)
eq_map() { echo "y=data(:,1):mm,f=data(:,$(($1 + 2))):N,dt=0.001"; }
sin_all=() sin_1khz=()
for t in 25mm0x1Hz 25mm0x25Hz 25mm0x5Hz 10mm1Hz 5mm3Hz 2mm5Hz; do
  for cur in 0 0x25 0x5 0x75 1; do
    "$rths" utfsm-convert "$data/mr_damper/${t}${cur}A.txt" --out "${t}${cur}A.csv" > /dev/null
    sin_all+=("${t}${cur}A.csv")
    if [[ "$t" == 10mm1Hz || "$t" == 5mm3Hz ]]; then sin_1khz+=("${t}${cur}A.csv"); fi
  done
done
# The authors' preprocessing of validacion.mat, a causal moving average of 300 samples (0.3 s) on
# both x and F (Validacion/sincronize.m), applied to sinusoid tests that the model fits: what that
# filter alone does to the score (0.3 s = 300 samples at 1 ms, 60 at 5 ms).
moving_average() {   # W IN OUT: MATLAB filter(ones(1,W)/W, 1, .) on u_mm, y_mm, f_kN of a rig record
  awk -v W="$1" 'BEGIN { FS = OFS = "," } /^#/ || /^t_s/ { print; next }
    { k = n % W; n++
      for (c = 2; c <= 4; c++) { if (n > W) s[c] -= b[c, k]; b[c, k] = $c; s[c] += $c; $c = sprintf("%.8g", s[c] / W) }
      print }' "$2" > "$3"
}
ma_tests=()
for cur in 0 0x25 0x5 0x75 1; do
  moving_average 300 "10mm1Hz${cur}A.csv" "ma300_10mm1Hz${cur}A.csv"
  moving_average 60 "25mm0x5Hz${cur}A.csv" "ma60_25mm0x5Hz${cur}A.csv"
  moving_average 60 "25mm0x25Hz${cur}A.csv" "ma60_25mm0x25Hz${cur}A.csv"
  ma_tests+=("ma300_10mm1Hz${cur}A.csv" "ma60_25mm0x5Hz${cur}A.csv" "ma60_25mm0x25Hz${cur}A.csv")
done
# Four fits, each run once per earthquake current. The 1 kHz fit ends with beta_c on the end of its
# range while beta is ~0 at every current (fit status FAILED, exit 3): --accept-unconverged.
for fit in all 1khz all_si 1khz_si; do
  if [[ "$fit" == all* ]]; then files=("${sin_all[@]}"); else files=("${sin_1khz[@]}"); fi
  extra=()
  if [[ "$fit" == *_si ]]; then extra=(--skew auto --inertia auto); fi
  log "damper, current-dependent, fit '$fit' (${#files[@]} sinusoid tests ${extra[*]}), held out: the earthquake tests"
  rm -f "eq_${fit}.toml"
  for j in 0 1 2 3 4; do
    check=("$eq")
    if [[ "$fit" == all && $j == 4 ]]; then check+=("${ma_tests[@]}"); fi
    lg="eq_${fit}_${eq_amps[$j]}A.log"
    rc=0
    "$rths" identify --damper "${files[@]}" --check "${check[@]}" --columns "$(eq_map $j),i=${eq_amps[$j]}" \
      "${extra[@]}" --accept-unconverged --out "eq_${fit}.toml" > "$lg" 2>&1 || rc=$?
    if [[ $rc != 0 ]]; then   # the same fit at every current: say so once and go on
      echo "  rths identify exit $rc: $(grep -v ': warning: ' "$lg" | tail -1) (all of it in $lg)"
      break
    fi
    if [[ $j == 0 ]]; then grep -E "^  (Levenberg|fit status|channel skew|load-cell inertia)|too small" "$lg"; fi
    sed -n '/held-out force error/,/^$/p' "$lg" | grep "%$" | sed "s|$eq|validacion.mat at ${eq_amps[$j]} A|"
  done
done
log "the same sinusoid tests unfiltered (training records of fit 'all'; the filtered ones are above)"
grep -E "^    (10mm1Hz|25mm0x5Hz|25mm0x25Hz)[0-9x]*A.csv .*%$" eq_all_1.0A.log
# rths diagnose takes one dt per diagnosis: train the 1 kHz sinusoids (10 mm / 1 Hz, 5 mm / 3 Hz) at
# one current, test the earthquake test (1 kHz) at the nearest current, with each fitted model.
pairs=("0x25 0" "0x5 1" "0x5 2" "0x75 3" "1 4")    # sinusoid current, earthquake column - 2
for fit in all 1khz; do
  for p in "${pairs[@]}"; do
    read -r cur j <<< "$p"
    d="diag_eq_${fit}_${cur}A_${eq_amps[$j]}A"
    rm -rf "$d"
    log "diagnose: model '$fit', train 10 mm / 1 Hz and 5 mm / 3 Hz at ${cur/x/.} A, test the earthquake test at ${eq_amps[$j]} A"
    "$rths" diagnose --train "10mm1Hz${cur}A.csv" "5mm3Hz${cur}A.csv" --test "$eq" --model "eq_${fit}.toml" \
      --columns "$(eq_map $j)" --current "${eq_amps[$j]}" --out "$d"
  done
done
# The model refitted with the skew: diagnose reads its damper and leaves its effects out (a note says
# so), and fits channel_skew itself on the training records.
if [[ -f eq_1khz_si.toml ]]; then
  rm -rf diag_eq_1khz_si_1A_1.0A
  log "diagnose: model '1khz_si' (its damper only), train 10 mm / 1 Hz and 5 mm / 3 Hz at 1 A, test the earthquake test at 1.0 A"
  "$rths" diagnose --train 10mm1Hz1A.csv 5mm3Hz1A.csv --test "$eq" --model eq_1khz_si.toml \
    --columns "$(eq_map 4)" --current 1.0 --out diag_eq_1khz_si_1A_1.0A
fi
log "done: $out"

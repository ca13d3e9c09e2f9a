#!/usr/bin/env bash
# The bundle of scripts/bundle.sh in a chroot that holds nothing but the bundle and Debian's
# busybox-static (/bin/busybox and links to its applets): no library of this Debian can be loaded
# there, so what runs, runs on the bundle's own glibc and libraries. Driven by tests/programs/bundle_test.cpp.
#
#   tests/bundle/chroot.sh TARBALL ROOT
#
# Makes ROOT afresh: bin/ (busybox), the bundle untarred in "ROOT/opt/rths bundle/" (a space in
# the path: the bundle must work wherever it is untarred), work/ (the SPEC of a 4-run sweep), and in
# a mount namespace of its own only /proc (mounted fresh) and /dev (bound); the mounts go with the
# namespace. Then, inside the chroot with an empty environment but PATH=/bin, it runs the steps
# below; each step's output is in ROOT/work/<step>.out and its files in ROOT/work/<step>/:
#   isolated  build/libexec/rths-run without the bundle's loader must fail (the host's is not there)
#   run       rths run --transport memq, 0.5 s
#   sweep     rths sweep spec.toml --jobs 2 (no gnuplot in the chroot: the table without figures)
#   tasks     rths sweep spec.toml --executor slurm --dry-run: the job script of the 2 array tasks,
#             which (task0, task1) then run as Slurm would run them (rths-sweep --task --chunk c),
#             and `rths sweep --resume` (resume) writes the table from their rows
# Exit 0 when every step exited 0 (tests/programs/bundle_test.cpp checks what they wrote); 1 when a step
# failed (its output is printed); 3 when this machine cannot run the test (the message says why).
# Needs root, unshare and mount (util-linux), chroot (coreutils), busybox-static.
set -euo pipefail
tarball=${1:-}; root=${2:-}
[[ -f $tarball && -n $root ]] || { echo "usage: $0 TARBALL ROOT" >&2; exit 2; }
tarball=$(cd "$(dirname "$tarball")" && pwd)/$(basename "$tarball")
need() { echo "chroot.sh: $*" >&2; exit 3; }
[[ $(id -u) -eq 0 ]] || need "needs root (chroot, mount)"
[[ -x /bin/busybox ]] || need "/bin/busybox not found: apt-get install busybox-static (scripts/bootstrap.sh installs it)"
if readelf -l /bin/busybox | grep -q INTERP; then
  need "/bin/busybox is dynamically linked (Debian's busybox): apt-get install busybox-static"
fi
for tool in unshare mount chroot tar; do command -v "$tool" >/dev/null || need "$tool not found"; done

rm -rf --one-file-system "$root"
mkdir -p "$root"/{bin,dev,proc,tmp,work,opt/"rths bundle"}
root=$(cd "$root" && pwd)
chmod 1777 "$root/tmp"
cp /bin/busybox "$root/bin/busybox"
for applet in $(/bin/busybox --list); do
  [[ $applet == busybox ]] || ln -s busybox "$root/bin/$applet"
done
tar xzf "$tarball" -C "$root/opt/rths bundle"
bundle="/opt/rths bundle/$(basename "$tarball" .tar.gz)"
[[ -x "$root$bundle/rths" ]] || need "$tarball does not hold $(basename "$bundle")/rths"

# 4 runs of 0.05 s (2 controllers x 2 damping ratios), 2 a task on Slurm.
cat > "$root/work/base.toml" <<'EOF'
[run]
name = "bundle_base"
duration_s = 0.05
EOF
cat > "$root/work/spec.toml" <<'EOF'
[sweep]
name = "bundle"
base = "base.toml"
record = ["steps", "peak_force_kN"]
[grid]
"controller.kind" = ["none", "ff"]
"structure.damping_ratio" = [0.02, 0.05]
[slurm]
runs_per_task = 2
EOF
cat > "$root/work/steps.sh" <<'EOF'
# Run by busybox sh inside the chroot: $1 is the bundle's folder.
set -eu
b=$1
cd /work
step() {
  name=$1; shift
  echo "== $name: $*"
  if "$@" > "/work/$name.out" 2>&1; then return 0; else rc=$?; fi
  cat "/work/$name.out"
  echo "chroot.sh: step $name failed (exit $rc): $*"
  exit 1
}
if "$b/build/libexec/rths-run" --help > /work/isolated.out 2>&1; then
  echo "chroot.sh: $b/build/libexec/rths-run ran without the bundle's loader: the chroot is not isolated"
  exit 1
fi
step run "$b/rths" run --transport memq --set run.duration_s=0.5 --out /work/run
step sweep "$b/rths" sweep /work/spec.toml --out /work/sweep --jobs 2
step tasks "$b/rths" sweep /work/spec.toml --executor slurm --out /work/tasks --dry-run
export SLURM_CPUS_PER_TASK=1
for c in 0 1; do
  export SLURM_ARRAY_TASK_ID=$c
  step "task$c" sh /work/tasks/slurm/task.sh
done
step resume "$b/rths" sweep /work/spec.toml --out /work/tasks --resume
EOF

unshare --mount --propagation private /bin/sh -c '
  set -e
  mount -t proc proc "$1/proc"
  mount --bind /dev "$1/dev"
  exec chroot "$1" /bin/env -i PATH=/bin HOME=/work /bin/sh /work/steps.sh "$2"
' sh "$root" "$bundle"

#!/usr/bin/env bash
# Makes rths-<version>-linux-x86_64.tar.gz: rths for x86-64 Linux hosts that are not Debian 12
# (RHEL, Rocky, Alma cluster nodes; docs/cluster.md). Run it on the Debian 12 machine that built rths.
#
# The bundle holds the `rths` front end (POSIX sh), every rths-* program, the scenarios and data they
# read, and every shared library the programs load, glibc and its loader included. Each program is
# started through the bundle's own loader (build/bin/rths-X is a 3-line sh script:
# `ld-linux-x86-64.so.2 --library-path <bundle>/build/lib <bundle>/build/libexec/rths-X`), so the
# host's libraries are never used: the host needs a Linux kernel (>= the version printed below, the
# one the bundled glibc requires), /bin/sh and readlink, and nothing else. Untar it anywhere, no root:
#   tar xzf rths-0.1.0-linux-x86_64.tar.gz -C /project/me && /project/me/rths-0.1.0-linux-x86_64/rths run
# It keeps the checkout's layout (rths, build/bin, scenarios/, data/), so every path of the docs holds.
# The loader sits in build/bin beside the wrappers: a program's /proc/self/exe is the loader, whose
# folder is then build/bin, where rths-run finds the participant programs and rths-sweep the path
# it writes into a Slurm job script (tools/slurm_flags.h).
#
# usage: bash scripts/bundle.sh [--build DIR] [--out DIR] [--no-build]
#   --build DIR  the CMake build tree (default: build); its rths_programs.txt lists the programs
#   --out DIR    where the .tar.gz goes (default: the build tree)
#   --no-build   do not build target rths_programs first (every program must be built already)
# Prints the tarball's path on its last line. Exit 1 when something is missing or a library of the
# bundle would come from outside it.
set -euo pipefail
src="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$src/build"
out=""
do_build=1
while (($#)); do
  case "$1" in
    --build) build="$(cd "$2" && pwd)"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --no-build) do_build=0; shift ;;
    -h|--help) sed -n '2,/^set -euo/p' "${BASH_SOURCE[0]}" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "bundle: unknown option '$1' (see: bash scripts/bundle.sh --help)" >&2; exit 2 ;;
  esac
done
out="${out:-$build}"
fail() { echo "bundle: $*" >&2; exit 1; }

[[ -f "$build/CMakeCache.txt" ]] || fail "$build is not a CMake build tree (cmake -S . -B build -G Ninja)"
((do_build)) && cmake --build "$build" --target rths_programs
list="$build/rths_programs.txt"
[[ -f "$list" ]] || fail "$list is missing: configure the build tree again (cmake -S $src -B $build)"
mapfile -t programs < "$list"
for p in "${programs[@]}"; do
  [[ -x "$p" ]] || fail "$p is not built: cmake --build $build --target rths_programs"
done
version="$(sed -n 's/^CMAKE_PROJECT_VERSION:[A-Z]*=//p' "$build/CMakeCache.txt")"
[[ -n "$version" ]] || fail "no CMAKE_PROJECT_VERSION in $build/CMakeCache.txt"
[[ "$(uname -m)" == x86_64 ]] || fail "the bundle is made for x86-64 hosts; this is $(uname -m)"
name="rths-$version-linux-x86_64"
mkdir -p "$out"
out="$(cd "$out" && pwd)"
stage="$(mktemp -d "$out/.bundle.XXXXXX")"
trap 'rm -rf "$stage"' EXIT
root="$stage/$name"
mkdir -p "$root/build/bin" "$root/build/libexec" "$root/build/lib"

# Programs, without debug information (strip: a RelWithDebInfo build has it), and every library ldd resolves for
# them, copied under its soname; the loader goes beside the wrappers (see the top).
loader=""
declare -A libs=()
for p in "${programs[@]}"; do
  prog="$(basename "$p")"
  strip --strip-debug -o "$root/build/libexec/$prog" "$p"
  while read -r soname arrow path _; do
    if [[ "$arrow" == "=>" && "$path" == /* ]]; then
      libs["$soname"]="$path"
    elif [[ "$soname" == /*/ld-linux-x86-64.so.2 ]]; then
      loader="$soname"
    elif [[ "$arrow" == "=>" && "$path" == "not" ]]; then
      fail "$p needs $soname, which is not found on this machine (ldd $p)"
    fi
  done < <(ldd "$p")
  cat > "$root/build/bin/$prog" <<'WRAPPER'
#!/bin/sh
# rths bundle (scripts/bundle.sh): runs build/libexec/<this name> with the bundle's glibc and libraries.
p=$(readlink -f "$0") || exit 127
b=${p%/*}
exec "$b/ld-linux-x86-64.so.2" --library-path "${b%/*}/lib" --argv0 "$0" "${b%/*}/libexec/${p##*/}" "$@"
WRAPPER
  chmod 755 "$root/build/bin/$prog"
done
[[ -n "$loader" ]] || fail "ldd named no ld-linux-x86-64.so.2 for the programs"
cp -L "$loader" "$root/build/bin/ld-linux-x86-64.so.2"
for soname in "${!libs[@]}"; do
  cp -L "${libs[$soname]}" "$root/build/lib/$soname"
done

# Every NEEDED library of every ELF in the bundle must be in build/lib (the loader is in build/bin).
for f in "$root"/build/libexec/* "$root"/build/lib/*; do
  while read -r needed; do
    [[ -f "$root/build/lib/$needed" || "$needed" == ld-linux-x86-64.so.2 ]] ||
      fail "$(basename "$f") needs $needed, which is not in the bundle"
  done < <(readelf -d "$f" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p')
done

# The front end, the files the programs read (scenarios, data, examples) and the docs.
cp "$src/rths" "$root/rths"
cp -r "$src/scenarios" "$src/data" "$src/examples" "$src/docs" "$root/"
(cd "$src" && cp README.md "$root/")

# What the host needs: the kernel the bundled glibc was built for (its ABI note), nothing else.
glibc="$("$root/build/bin/ld-linux-x86-64.so.2" --version | sed -n '1s/.*version \([0-9][0-9.]*[0-9]\).*/\1/p')"
kernel="$(readelf -n "$root/build/lib/libc.so.6" | sed -n 's/.*OS: Linux, ABI: \([0-9.]*\).*/\1/p')"
commit="$(git -C "$src" describe --always --dirty 2>/dev/null || echo unknown)"
cat > "$root/BUNDLE.txt" <<EOF
rths $version (commit $commit) for x86-64 Linux, made by scripts/bundle.sh on $(. /etc/os-release; echo "$PRETTY_NAME").

Runs on any x86-64 Linux with kernel >= $kernel, /bin/sh and readlink: it brings its own glibc
$glibc, loader and libraries (build/lib) and uses none of the host's. Untar anywhere, no root:
  $name/rths run --transport memq
  $name/rths sweep SPEC.toml --out DIR
On a cluster (docs/cluster.md): put this folder on the shared filesystem; the Slurm job script
runs $name/build/bin/rths-sweep. Not bundled: gnuplot (figures are left out where it is
missing; the tables are the result), Java, Python, Octave (examples/), the LCM tools.
EOF

tar --sort=name --owner=0 --group=0 --numeric-owner -C "$stage" -czf "$stage/$name.tar.gz" "$name"
mv "$stage/$name.tar.gz" "$out/$name.tar.gz"
echo "bundle: ${#programs[@]} programs, ${#libs[@]} libraries (glibc $glibc; the host needs Linux >= $kernel)"
echo "$out/$name.tar.gz"

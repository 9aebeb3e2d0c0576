#!/usr/bin/env bash
# Time the README's two commands on a fresh Debian 12 machine (docs/building.md, "How long the
# README's commands take"). The machine is a debootstrap root of bookworm holding what a new
# machine of this kind has before the README is run: Debian's python3 (3.11) with pip, venv and
# its headers, gcc, g++, git, ca-certificates; no apt lists, no caches. It is made once
# (debootstrap, a few minutes) and kept as $FRESH_DIR/pristine.tar. Each command runs as root in
# its own fresh copy of it, on a clone of COMMIT, in a private mount namespace (its own /proc,
# /sys and a /dev of its own: nothing is mounted on the host), with a clean environment
# (no pip mirror, no PYTHONDONTWRITEBYTECODE): apt and pip fetch from Debian and PyPI.
# Prints every line the command prints (setup.sh: one per step, with its seconds), then each
# part's wall and CPU time with the load average before and after it.
# Usage, as root on the host: bash scripts/fresh_machine.sh [1|2|both] [COMMIT]
#   1: `bash scripts/setup.sh && pyspline reproduce --out out`
#   2: `bash scripts/setup.sh --tests && pytest -q -n 2 tests`, from a fresh copy again
# FRESH_DIR (default /work/fresh) holds pristine.tar, the copies run1/, run2/ and their logs.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
which="${1:-both}"
commit="$(git -C "$repo" rev-parse "${2:-HEAD}")"
dir="${FRESH_DIR:-/work/fresh}"
pristine="$dir/pristine.tar"
mkdir -p "$dir"

make_pristine() {
  local root="$dir/pristine"
  command -v debootstrap >/dev/null || apt-get install -y -qq debootstrap >/dev/null
  rm -rf --one-file-system "$root"
  debootstrap --variant=minbase \
    --include=python3,python3-pip,python3-venv,python3-dev,gcc,g++,git,ca-certificates \
    bookworm "$root" http://deb.debian.org/debian >"$dir/debootstrap.log" 2>&1
  rm -f "$root/etc/apt/sources.list"   # Debian 12's own format, as on a new machine
  cat >"$root/etc/apt/sources.list.d/debian.sources" <<'EOF'
Types: deb
URIs: http://deb.debian.org/debian
Suites: bookworm bookworm-updates
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg

Types: deb
URIs: http://deb.debian.org/debian-security
Suites: bookworm-security
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
EOF
  rm -rf "$root"/var/lib/apt/lists/* "$root"/var/cache/apt/archives/*.deb \
    "$root"/var/cache/apt/*.bin
  mkdir -p "$root/var/lib/apt/lists/partial"
  tar -C "$root" -cf "$pristine" . && rm -rf --one-file-system "$root"
}

# measure N: the README's command N in a fresh copy
measure() {
  local n="$1" copy="$dir/run$1" line
  line="$(git -C "$repo" show "$commit:README.md" | sed -n '/^```bash$/,/^```$/p' | sed -n "$((n + 1))p")"
  [ -n "$line" ] || { echo "no command $n in README.md at $commit" >&2; return 1; }
  if grep -q " $copy/" /proc/mounts; then echo "$copy has mounts: not removing it" >&2; return 1; fi
  rm -rf --one-file-system "$copy" && mkdir -p "$copy"
  tar -C "$copy" -xf "$pristine" || return 1
  cp /etc/resolv.conf "$copy/etc/resolv.conf"
  # the host's local CA certificates (those of its HTTPS egress), which a new machine has too
  if compgen -G "/usr/local/share/ca-certificates/*.crt" >/dev/null; then
    cp /usr/local/share/ca-certificates/*.crt "$copy/usr/local/share/ca-certificates/"
    chroot "$copy" update-ca-certificates >/dev/null 2>&1
  fi
  git clone -q --no-local "$repo" "$copy/root/pyspline" || return 1
  git -C "$copy/root/pyspline" checkout -q "$commit" || return 1
  cat >"$copy/root/measure.sh" <<'EOF'
cd /root/pyspline
line="$1"; parts=(); total=0
while [[ "$line" == *" && "* ]]; do parts+=("${line%% && *}"); line="${line#* && }"; done
parts+=("$line")
for part in "${parts[@]}"; do
  echo "measure: $part  (load before: $(cut -d' ' -f1-3 /proc/loadavg))"
  TIMEFORMAT="measure: %0R s wall, %0U s user + %0S s sys: $part"
  t0=$SECONDS
  { time bash -c "$part"; } 2>&1 || { echo "measure: FAILED (exit $?): $part"; exit 1; }
  total=$((total + SECONDS - t0))
  echo "measure: load after: $(cut -d' ' -f1-3 /proc/loadavg)"
done
echo "measure: total $total s wall: $1"
EOF
  echo "== fresh Debian 12 root, commit ${commit:0:7}, command $n: $line" | tee "$dir/run$n.log"
  unshare --mount --propagation private bash -c '
    set -e; c="$1"
    mount -t proc proc "$c/proc"; mount -t sysfs -o ro sysfs "$c/sys"
    mount -t tmpfs -o mode=755 tmpfs "$c/dev"
    for d in null:1:3 zero:1:5 full:1:7 random:1:8 urandom:1:9 tty:5:0; do
      IFS=: read -r name major minor <<<"$d"; mknod -m 666 "$c/dev/$name" c "$major" "$minor"
    done
    mkdir "$c/dev/pts" "$c/dev/shm"; mount -t tmpfs -o mode=1777 tmpfs "$c/dev/shm"
    mount -t devpts -o newinstance,ptmxmode=0666 devpts "$c/dev/pts"; ln -s pts/ptmx "$c/dev/ptmx"
    ln -s /proc/self/fd "$c/dev/fd"
    exec chroot "$c" /usr/bin/env -i HOME=/root LANG=C.UTF-8 TERM=dumb \
      PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
      bash /root/measure.sh "$2"' _ "$copy" "$line" 2>&1 | tee -a "$dir/run$n.log"
}

[ -f "$pristine" ] || make_pristine
case "$which" in
  1|2) runs=("$which") ;;
  both) runs=(1 2) ;;
  *) echo "usage: bash scripts/fresh_machine.sh [1|2|both] [COMMIT]" >&2; exit 2 ;;
esac
rc=0
for n in "${runs[@]}"; do measure "$n" || rc=1; done
echo "== summary: per step and in all (load average: 1, 5, 15 min)"
for n in "${runs[@]}"; do grep -h '^==\|^setup:\|^measure:' "$dir/run$n.log"; done
exit $rc

#!/usr/bin/env bash
# Builds the robocal container image from the top-level Dockerfile with podman, runs it, and checks that
# run without API keys it refuses to start (it binds 0.0.0.0 in its container); run with a key from
# `robocal keygen` passed as a secret file (ROBOCAL_API_KEYS_FILE), /healthz answers on a loopback-published
# port, a write without the key is 401 and with it 201; then removes the test container and volume.
#
#   sudo scripts/docker-check.sh          # as root; nothing else to prepare
#
# Works with no container registry and no network inside the build:
#   * podman, runc, debootstrap (and curl) come from Debian's packages (installed if missing);
#   * the base images are made here from a debootstrap'ed Debian rootfs and `podman import`ed, once, then
#     reused (see `podman images localhost/robocal-*`):
#       localhost/robocal-base:bookworm             minbase + curl        -> the runtime stage
#       localhost/robocal-builder:bookworm-rust...  minbase + gcc + a copy of this machine's Rust toolchain
#                                                   (the one `rustc` in this repository resolves to)
#   * crates are `cargo vendor`ed into a staged copy of the build context (the repository itself is not
#     touched), so `podman build --network=none` compiles offline.
# Idempotent: base images and the cargo target cache (a build cache mount) are reused; a rerun rebuilds only
# what changed. Exits non-zero on any failure.
#
# Environment (all optional):
#   ROBOCAL_IMAGE            tag of the image built            (default localhost/robocal:dev)
#   ROBOCAL_DOCKER_CACHE     work/cache directory              (default /var/cache/robocal-docker)
#   DEBIAN_MIRROR            mirror for debootstrap            (default http://deb.debian.org/debian)
#   ROBOCAL_REBUILD_BASE=1   make the base images again
#   ROBOCAL_KEEP_IMAGE=0     remove the built image at the end (default: keep it)
#   ROBOCAL_HEALTH_TIMEOUT   seconds to wait for /healthz      (default 60)
#   PODMAN_STORAGE_DRIVER    e.g. vfs, where overlay does not work (default: podman's own, overlay here)
#
# What podman needed in this sandbox (Debian 12, root, cgroup v1, no systemd): `--runtime runc`,
# `--cgroup-manager cgroupfs` and explicit `--ulimit`s (set below, harmless elsewhere); overlay storage and
# the default CNI bridge network with `-p 127.0.0.1::8080` worked (no slirp4netns/pasta, no --network=host);
# builds run with `--network none`. `--format docker` keeps the HEALTHCHECK. Without systemd podman cannot
# schedule health checks (it logs "unable to get systemd connection"), so the test container runs with
# `--health-interval disable` and this script runs the image's HEALTHCHECK once with `podman healthcheck run`.
# `--layers=false`: the builder stage's layers (~1 GB, new with every source change) are not kept; the cargo
# target dir persists in the build's cache mount instead (/var/tmp/buildah-cache/robocal-target).
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
SUITE=bookworm
MIRROR=${DEBIAN_MIRROR:-http://deb.debian.org/debian}
CACHE=${ROBOCAL_DOCKER_CACHE:-/var/cache/robocal-docker}
IMAGE=${ROBOCAL_IMAGE:-localhost/robocal:dev}
BASE_IMAGE=localhost/robocal-base:$SUITE
HEALTH_TIMEOUT=${ROBOCAL_HEALTH_TIMEOUT:-60}
RUNTIME_PKGS=curl
BUILDER_PKGS=gcc,libc6-dev,pkg-config,ca-certificates
HOST_PKGS=(podman runc debootstrap curl ca-certificates tar)

PODMAN=(podman --runtime runc --cgroup-manager cgroupfs)
if [[ -n "${PODMAN_STORAGE_DRIVER:-}" ]]; then PODMAN+=(--storage-driver "$PODMAN_STORAGE_DRIVER"); fi
# podman's default rlimits (nofile 1048576, nproc 4194304) are above what this sandbox lets runc set
# ("error setting rlimit type 7/6: operation not permitted"): use the host's hard limits, nproc also capped
# at kernel.pid_max (here 32768; 36000 was already refused).
NOFILE=$(ulimit -Hn); NPROC=$(ulimit -Hu); PID_MAX=$(cat /proc/sys/kernel/pid_max 2>/dev/null || echo 32768)
[[ $NOFILE == unlimited ]] && NOFILE=1048576
[[ $NPROC == unlimited || $NPROC -gt $PID_MAX ]] && NPROC=$PID_MAX
ULIMITS=(--ulimit "nofile=$NOFILE:$NOFILE" --ulimit "nproc=$NPROC:$NPROC")

NAME=robocal-check-$$
VOLUME=robocal-check-data-$$
CTX=""
ROOTFS_TMP=""

say() { printf '\n==> %s\n' "$*" >&2; }
run() { if [[ $1 == nosd ]]; then printf '+ %s\n' "${*:2}" >&2; else printf '+ %s\n' "$*" >&2; fi; "$@"; }
# podman 4.3 logs "unable to get systemd connection" for containers with a health check when systemd is not
# running, even with --health-interval disable; drop that line, keep every other message.
nosd() { "$@" 2> >(grep -v 'unable to get systemd connection' >&2); }
die() { printf 'docker-check: FAILED: %s\n' "$*" >&2; exit 1; }

cleanup() {
    local rc=$?
    set +e
    if [[ -n "${STARTED:-}" ]]; then
        say "cleaning up"
        run nosd "${PODMAN[@]}" rm -f -t 5 "$NAME" >/dev/null
        run "${PODMAN[@]}" volume rm -f "$VOLUME" >/dev/null
        if [[ "${ROBOCAL_KEEP_IMAGE:-1}" == 0 ]]; then run "${PODMAN[@]}" rmi -f "$IMAGE" >/dev/null; fi
    fi
    [[ -n "$CTX" ]] && rm -rf "$CTX"
    if [[ -n "$ROOTFS_TMP" && -d "$ROOTFS_TMP" ]]; then
        # debootstrap leaves /proc, /sys mounted in the target when it fails half-way
        grep -o " $ROOTFS_TMP[^ ]*" /proc/mounts | sort -r | xargs -r -n1 umount -l 2>/dev/null
        rm -rf "$ROOTFS_TMP"
    fi
    if ((rc != 0)); then printf '\ndocker-check: FAILED (exit %d)\n' "$rc" >&2; fi
    exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

[[ $(id -u) == 0 ]] || die "run as root (rootful podman and debootstrap); e.g. sudo $0"
[[ -f "$ROOT/Dockerfile" ]] || die "no Dockerfile in $ROOT"
mkdir -p "$CACHE"
exec 9>"$CACHE/lock"
flock -n 9 || { echo "docker-check: another run holds $CACHE/lock; waiting" >&2; flock 9; }

# ---------------------------------------------------------------------------------------------------------
say "host tools"
missing=()
for p in "${HOST_PKGS[@]}"; do
    dpkg-query -W -f '${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if ((${#missing[@]})); then
    run apt-get update -q
    run env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
else
    echo "installed: ${HOST_PKGS[*]}"
fi
run "${PODMAN[@]}" --version

# The Rust toolchain this repository builds with (rustup honours a rust-toolchain file, if any).
for d in "$HOME/.cargo/bin" /usr/local/cargo/bin; do [[ -d $d ]] && PATH="$d:$PATH"; done
command -v cargo >/dev/null || die "no cargo on PATH (the builder image copies the host's Rust toolchain)"
SYSROOT=$(cd "$ROOT" && rustc --print sysroot) || die "rustc --print sysroot failed"
RUSTC_VERSION=$(cd "$ROOT" && rustc --version)            # rustc 1.95.0 (59807616e 2026-04-14)
RUST_TAG=$(awk '{v=$2; h=$3; gsub(/[()]/, "", h); print v (h ? "-" h : "")}' <<<"$RUSTC_VERSION")
BUILDER_IMAGE=localhost/robocal-builder:$SUITE-rust$RUST_TAG
echo "toolchain: $RUSTC_VERSION at $SYSROOT"
[[ -x "$SYSROOT/bin/cargo" && -x "$SYSROOT/bin/rustc" ]] || die "$SYSROOT/bin has no cargo/rustc"

image_exists() { "${PODMAN[@]}" image exists "$1"; }

# make_base TAG PACKAGES [TOOLCHAIN]: debootstrap a minbase rootfs, trim it, podman import it as TAG.
make_base() {
    local tag=$1 pkgs=$2 toolchain=${3:-} path=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin
    ROOTFS_TMP=$(mktemp -d "$CACHE/rootfs.XXXXXX")
    local rootfs=$ROOTFS_TMP/rootfs
    mkdir -p "$CACHE/debs"
    echo "+ debootstrap --variant=minbase --include=$pkgs --cache-dir=$CACHE/debs $SUITE $rootfs $MIRROR" >&2
    debootstrap --variant=minbase --include="$pkgs" --cache-dir="$CACHE/debs" \
        "$SUITE" "$rootfs" "$MIRROR" >"$ROOTFS_TMP/debootstrap.log" 2>&1 ||
        { tail -30 "$ROOTFS_TMP/debootstrap.log" >&2; die "debootstrap failed (log above)"; }
    # The same trimming as Debian's -slim images: no apt lists or package cache, docs, man pages, locales.
    rm -rf "$rootfs"/var/cache/apt/* "$rootfs"/var/lib/apt/lists/* "$rootfs"/var/log/* \
        "$rootfs"/usr/share/man/* "$rootfs"/usr/share/info/* "$rootfs"/usr/share/locale/* "$rootfs"/tmp/*
    find "$rootfs/usr/share/doc" -mindepth 1 -not -name copyright -not -type d -delete
    find "$rootfs/usr/share/doc" -mindepth 1 -type d -empty -delete
    find "$rootfs/dev" -mindepth 1 -delete     # the container runtime provides /dev
    cat >"$rootfs/etc/apt/apt.conf.d/docker-clean" <<'EOF'
DPkg::Post-Invoke { "rm -f /var/cache/apt/archives/*.deb /var/cache/apt/archives/partial/*.deb /var/cache/apt/*.bin || true"; };
APT::Update::Post-Invoke { "rm -f /var/cache/apt/archives/*.deb /var/cache/apt/archives/partial/*.deb /var/cache/apt/*.bin || true"; };
Dir::Cache::pkgcache ""; Dir::Cache::srcpkgcache "";
EOF
    local changes=()
    if [[ -n "$toolchain" ]]; then
        # Only what compiling needs: cargo, rustc and their libraries; no docs (share/), no rust-src.
        run mkdir -p "$rootfs/usr/local/rust/bin" "$rootfs/usr/local/cargo"
        run cp -a "$toolchain/bin/cargo" "$toolchain/bin/rustc" "$rootfs/usr/local/rust/bin/"
        run tar -C "$toolchain" --exclude=./lib/rustlib/src -cf - ./lib | tar -C "$rootfs/usr/local/rust" -xf -
        [[ -d "$toolchain/libexec" ]] && run cp -a "$toolchain/libexec" "$rootfs/usr/local/rust/"
        path=/usr/local/rust/bin:/usr/local/cargo/bin:$path
        changes+=(--change "ENV CARGO_HOME=/usr/local/cargo")
    fi
    changes+=(--change "ENV PATH=$path" --change 'CMD ["/bin/bash"]')
    say "importing $tag ($(du -sh "$rootfs" | cut -f1) rootfs)"
    tar --numeric-owner -C "$rootfs" -cf - . |
        run "${PODMAN[@]}" import "${changes[@]}" --message "debootstrap --variant=minbase $SUITE +$pkgs" - "$tag"
    rm -rf "$ROOTFS_TMP"
    ROOTFS_TMP=""
}

say "base images"
for pair in "$BASE_IMAGE|$RUNTIME_PKGS|" "$BUILDER_IMAGE|$BUILDER_PKGS|$SYSROOT"; do
    IFS='|' read -r tag pkgs tc <<<"$pair"
    if [[ "${ROBOCAL_REBUILD_BASE:-0}" != 1 ]] && image_exists "$tag"; then
        echo "present: $tag"
    else
        say "making $tag (debootstrap $SUITE minbase + $pkgs${tc:+ + Rust toolchain})"
        make_base "$tag" "$pkgs" "$tc"
    fi
done
run "${PODMAN[@]}" run "${ULIMITS[@]}" --rm --no-healthcheck --network none "$BUILDER_IMAGE" sh -c 'cargo --version && rustc --version && cc --version | head -1'

# ---------------------------------------------------------------------------------------------------------
say "staging the build context (working tree + vendored crates)"
CTX=$(mktemp -d "$CACHE/context.XXXXXX")
# The working tree as it is (uncommitted and untracked files too); .dockerignore filters it again.
run tar -C "$ROOT" --exclude=./target --exclude=./.git --exclude=./vendor -cf - . | tar -C "$CTX" -xf -
(cd "$CTX" && run cargo vendor --quiet --versioned-dirs vendor >/dev/null) ||
    die "cargo vendor failed (crates.io must be reachable, or the crates already in ~/.cargo/registry)"
cmp -s "$ROOT/Cargo.lock" "$CTX/Cargo.lock" ||
    echo "note: Cargo.lock was out of date; the staged copy was updated (the repository's is untouched)"
echo "context: $(du -sh "$CTX" | cut -f1) ($(ls "$CTX/vendor" | wc -l) vendored crates)"

say "building $IMAGE"
OLD_ID=$("${PODMAN[@]}" image inspect --format '{{.Id}}' "$IMAGE" 2>/dev/null || true)
t0=$SECONDS
run "${PODMAN[@]}" build "${ULIMITS[@]}" --format docker --network none --pull=never --layers=false \
    --build-arg BUILDER_IMAGE="$BUILDER_IMAGE" --build-arg RUNTIME_IMAGE="$BASE_IMAGE" \
    -f "$CTX/Dockerfile" -t "$IMAGE" "$CTX"
BUILD_SECONDS=$((SECONDS - t0))
rm -rf "$CTX"
CTX=""
NEW_ID=$("${PODMAN[@]}" image inspect --format '{{.Id}}' "$IMAGE")
if [[ -n "$OLD_ID" && "$OLD_ID" != "$NEW_ID" ]]; then
    "${PODMAN[@]}" rmi "$OLD_ID" >/dev/null 2>&1 || true    # the previous build, now untagged
fi
SIZE_BYTES=$("${PODMAN[@]}" image inspect --format '{{.Size}}' "$IMAGE")
SIZE_MB=$(awk -v b="$SIZE_BYTES" 'BEGIN { printf "%.1f", b / 1e6 }')
BIN_MB=$("${PODMAN[@]}" run "${ULIMITS[@]}" --rm --no-healthcheck --network none --entrypoint stat "$IMAGE" -c %s /usr/local/bin/robocal |
    awk '{ printf "%.1f", $1 / 1e6 }')
echo "built in ${BUILD_SECONDS}s: $IMAGE ${SIZE_MB} MB (robocal binary ${BIN_MB} MB)"

# ---------------------------------------------------------------------------------------------------------
say "checking the image"
STARTED=1
cfg=$("${PODMAN[@]}" image inspect --format \
    'user={{.Config.User}} volumes={{.Config.Volumes}} healthcheck={{.Config.Healthcheck.Test}} env={{.Config.Env}}' "$IMAGE")
echo "$cfg"
grep -q 'user=10001' <<<"$cfg" || die "the image does not run as the non-root user"
grep -q '/data' <<<"$cfg" || die "the image declares no /data volume"
grep -q 'healthz' <<<"$cfg" || die "the image has no HEALTHCHECK on /healthz"
run "${PODMAN[@]}" run "${ULIMITS[@]}" --rm --no-healthcheck --network none "$IMAGE" --version
run "${PODMAN[@]}" volume create "$VOLUME" >/dev/null
run "${PODMAN[@]}" run "${ULIMITS[@]}" --rm --no-healthcheck --network none -v "$VOLUME:/data" --entrypoint sh "$IMAGE" \
    -c 'echo "uid=$(id -u) gid=$(id -g) DATABASE_URL=$DATABASE_URL"; test "$(id -u)" != 0 &&
        touch /data/.write-test && rm /data/.write-test && echo "/data is writable"' ||
    die "the non-root user cannot write the /data volume"

say "refusing to serve without a key"
# Run without keys, the image (bound to 0.0.0.0 in its container) must not serve writes: it refuses to start.
if "${PODMAN[@]}" run "${ULIMITS[@]}" --rm --no-healthcheck --network none -v "$VOLUME:/data" "$IMAGE" \
        >"$CACHE/nokey.log" 2>&1; then
    cat "$CACHE/nokey.log" >&2
    die "the image started without API keys"
fi
cat "$CACHE/nokey.log"
grep -q 'ROBOCAL_API_KEYS' "$CACHE/nokey.log" || die "the refusal does not name ROBOCAL_API_KEYS"

say "serving with a key"
ENTRY=$("${PODMAN[@]}" run "${ULIMITS[@]}" --rm --no-healthcheck --network none "$IMAGE" keygen --role admin)
KEY=${ENTRY%:*}
[[ ${#KEY} -ge 40 && "$ENTRY" == *:admin ]] || die "robocal keygen printed '$ENTRY'"
# The key as a secret file, as deploy/compose.yaml passes it.
install -m 0644 /dev/null "$CACHE/api_keys"
echo "$ENTRY" >"$CACHE/api_keys"
run nosd "${PODMAN[@]}" run "${ULIMITS[@]}" -d --health-interval disable --name "$NAME" -p 127.0.0.1::8080 -v "$VOLUME:/data" \
    -v "$CACHE/api_keys:/run/secrets/robocal_api_keys:ro" -e ROBOCAL_API_KEYS_FILE=/run/secrets/robocal_api_keys \
    "$IMAGE" >/dev/null
HOSTPORT=$("${PODMAN[@]}" port "$NAME" 8080/tcp | head -1)
[[ "$HOSTPORT" == 127.0.0.1:* ]] || die "port 8080 not published on loopback (got '$HOSTPORT')"
URL=http://$HOSTPORT/healthz
echo "waiting up to ${HEALTH_TIMEOUT}s for $URL"
BODY=""
for ((i = 0; i < HEALTH_TIMEOUT; i++)); do
    if BODY=$(curl -fsS --max-time 2 "$URL" 2>/dev/null); then break; fi
    BODY=""
    state=$("${PODMAN[@]}" inspect --format '{{.State.Status}}' "$NAME" 2>/dev/null || echo gone)
    if [[ "$state" != running ]]; then
        "${PODMAN[@]}" logs "$NAME" >&2 || true
        die "the container stopped ($state) before /healthz answered; its log is above"
    fi
    sleep 1
done
if [[ -z "$BODY" ]]; then
    "${PODMAN[@]}" logs "$NAME" >&2 || true
    die "/healthz did not answer within ${HEALTH_TIMEOUT}s; the container log is above"
fi
ROBOTS=http://$HOSTPORT/v1/robots
code=$(curl -sS -o /dev/null -w '%{http_code}' --max-time 5 -X POST "$ROBOTS" \
    -H 'Content-Type: application/json' -d '{"preset": "ur5"}')
echo "a write without a key: $code"
[[ "$code" == 401 ]] || die "a write without a key answered $code, not 401"
code=$(curl -sS -o /dev/null -w '%{http_code}' --max-time 5 -X POST "$ROBOTS" -H "Authorization: Bearer $KEY" \
    -H 'Content-Type: application/json' -d '{"preset": "ur5"}')
echo "a write with the key: $code"
[[ "$code" == 201 ]] || die "a write with the key answered $code, not 201"
run curl -sS -i --max-time 5 "$URL"
echo
run nosd "${PODMAN[@]}" healthcheck run "$NAME" && echo "HEALTHCHECK: healthy" ||
    die "the image's HEALTHCHECK failed inside the container"
run "${PODMAN[@]}" exec "$NAME" ls -ln /data
"${PODMAN[@]}" exec "$NAME" sh -c 'ls /data/robocal.db >/dev/null 2>&1' ||
    echo "note: /data/robocal.db not created yet (the server may open the database lazily)"
"${PODMAN[@]}" logs "$NAME" 2>&1 | tail -20

say "OK: $IMAGE (${SIZE_MB} MB, built in ${BUILD_SECONDS}s) refuses to serve without a key; with one, /healthz: $BODY, a write 401 without the key and 201 with it"

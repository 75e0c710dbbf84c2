# robocal service image: multi-stage build, small Debian runtime, non-root, database on a volume.
#
#   docker build -t robocal .                      # with a Docker engine and registry access
#   scripts/docker-check.sh                        # podman, offline: local base images + vendored crates
#
# Build arguments (scripts/docker-check.sh passes locally made images):
#   BUILDER_IMAGE  Debian bookworm with a Rust toolchain (cargo on PATH) and gcc
#   RUNTIME_IMAGE  Debian bookworm; curl is installed with apt unless it is already there
# If the build context holds a `vendor/` directory (made by `cargo vendor`), crates come from it and the build
# needs no network; otherwise cargo downloads them from crates.io.

ARG BUILDER_IMAGE=docker.io/library/rust:1-slim-bookworm
ARG RUNTIME_IMAGE=docker.io/library/debian:bookworm-slim

FROM ${BUILDER_IMAGE} AS builder
WORKDIR /src
# No debug info in the image's binary (the release profile keeps some for profiling on a workstation);
# SQLX_OFFLINE makes sqlx's query macros, if used, read the checked-in `.sqlx/` data instead of a database.
ENV CARGO_TERM_COLOR=never \
    CARGO_INCREMENTAL=0 \
    CARGO_PROFILE_RELEASE_DEBUG=0 \
    CARGO_PROFILE_RELEASE_STRIP=symbols \
    SQLX_OFFLINE=true
COPY . .
# The cache mount keeps target/ between builds, so a rebuild compiles only what changed.
RUN --mount=type=cache,id=robocal-target,target=/src/target \
    set -eu; \
    if [ -d vendor ]; then \
        set -- --offline \
            --config 'source.crates-io.replace-with="vendored-sources"' \
            --config 'source.vendored-sources.directory="vendor"'; \
    fi; \
    cargo --version; \
    cargo build --release --locked --bin robocal "$@"; \
    install -D -m 0755 target/release/robocal /out/robocal

FROM ${RUNTIME_IMAGE} AS runtime
RUN set -eu; \
    if ! command -v curl >/dev/null 2>&1; then \
        apt-get update; \
        DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends curl; \
        rm -rf /var/lib/apt/lists/*; \
    fi; \
    groupadd --system --gid 10001 robocal; \
    useradd --system --uid 10001 --gid 10001 --home-dir /data --no-create-home \
        --shell /usr/sbin/nologin robocal; \
    mkdir -p /data; \
    chown 10001:10001 /data; \
    chmod 0750 /data
COPY --from=builder /out/robocal /usr/local/bin/robocal

LABEL org.opencontainers.image.title="robocal" \
      org.opencontainers.image.description="Industrial robot calibration and false-target preprocessor service" \
      org.opencontainers.image.licenses="MIT"

# NO_COLOR: plain log lines (no ANSI escapes) for `docker logs` and log collectors.
ENV DATABASE_URL="sqlite:///data/robocal.db?mode=rwc" \
    NO_COLOR=1
WORKDIR /data
VOLUME ["/data"]
USER 10001:10001
EXPOSE 8080
# HEALTHCHECK is kept by Docker and by `podman build --format docker` (the OCI format drops it).
HEALTHCHECK --interval=30s --timeout=5s --start-period=15s --retries=3 \
    CMD ["curl", "-fsS", "-o", "/dev/null", "--max-time", "4", "http://127.0.0.1:8080/healthz"]
# It serves 0.0.0.0 inside the container, so without API keys it refuses to start (docs/docker.md): pass
# ROBOCAL_API_KEYS_FILE=/run/secrets/robocal_api_keys with a secret made by `robocal keygen`, or ROBOCAL_API_KEYS.
ENTRYPOINT ["robocal"]
CMD ["serve", "--bind", "0.0.0.0:8080"]

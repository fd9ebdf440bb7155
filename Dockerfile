# syntax=docker/dockerfile:1
# tetherplan: the HTTP service and chart page in a small Debian image.
#
#   docker build -t tetherplan .
#   docker run --rm -p 127.0.0.1:8080:8080 -v tetherplan-data:/data tetherplan
#
# Then open http://localhost:8080/ (chart page), /docs (API), /healthz.
# Jobs persist in the SQLite database on the /data volume.
#
# Security: inside the container the server binds 0.0.0.0:8080 (it must, to
# be reachable through the port mapping) and logs a loud warning when no
# tokens are set. Publish on loopback as above, or before exposing the port:
#   -e TETHERPLAN_API_TOKENS=token1,token2    every /api route then needs
#                                             "Authorization: Bearer token1"
#   -e TETHERPLAN_ALLOWED_HOSTS=plan.example.org   Host names besides
#                                             localhost (others get 421)
# Connection limits: TETHERPLAN_HEADER_TIMEOUT_S (5), TETHERPLAN_BODY_TIMEOUT_S
# (10), TETHERPLAN_MAX_CONNECTIONS (10000, clamped below the file limit).
#
# The image listens on 0.0.0.0: give it API tokens, or anyone who can reach
# the port can read, submit and cancel every job (the server logs a loud
# warning when it has none):
#   docker run --rm -p 8080:8080 -v tetherplan-data:/data \
#     -e TETHERPLAN_API_TOKENS="$(openssl rand -hex 24),$(openssl rand -hex 24)" \
#     --hostname tetherplan-1 tetherplan
# A fixed --hostname lets a restarted container take over its interrupted job
# at once; otherwise it is taken over when its lease (TETHERPLAN_JOB_LEASE_S,
# 30 s) expires.

# ---- build: release binary ----
FROM rust:1.95-slim-bookworm AS build
WORKDIR /src
COPY . .
# BuildKit cache mounts keep the crate registry and target dir between builds;
# the binary is copied out of the cached target dir.
RUN --mount=type=cache,target=/usr/local/cargo/registry \
    --mount=type=cache,target=/src/target \
    cargo build --release --locked --bin tetherplan \
    && cp target/release/tetherplan /usr/local/bin/tetherplan

# ---- runtime: the binary (the page is built into it) ----
FROM debian:bookworm-slim
RUN useradd --system --uid 10001 --home-dir /data --shell /usr/sbin/nologin tetherplan \
    && mkdir -p /data && chown tetherplan /data
COPY --from=build /usr/local/bin/tetherplan /usr/local/bin/tetherplan
ENV TETHERPLAN_DB=/data/tetherplan.db \
    RUST_LOG=info
VOLUME ["/data"]
WORKDIR /data
USER tetherplan
EXPOSE 8080
# No curl in the slim image: bash's /dev/tcp asks /healthz.
HEALTHCHECK --interval=30s --timeout=3s --start-period=5s \
    CMD ["bash", "-c", "exec 3<>/dev/tcp/127.0.0.1/8080 && printf 'GET /healthz HTTP/1.0\\r\\n\\r\\n' >&3 && head -n1 <&3 | grep -q ' 200 '"]
# Exec form: tetherplan is PID 1 and gets SIGTERM for its graceful shutdown.
ENTRYPOINT ["/usr/local/bin/tetherplan"]
CMD ["serve", "--addr", "0.0.0.0:8080"]

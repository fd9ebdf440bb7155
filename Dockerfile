# syntax=docker/dockerfile:1
# tetherplan: the HTTP service and chart page in a small Debian image.
#
#   docker build -t tetherplan .
#   docker run --rm -p 127.0.0.1:8080:8080 -v tetherplan-data:/data tetherplan
#
# Then open http://localhost:8080/ (chart page), /docs (API), /healthz.
# Jobs persist in the SQLite database on the /data volume.
#
# Security (the server binds 0.0.0.0:8080 inside the container; API tokens,
# Host allow-list, connection limits) and the fixed --hostname for job
# takeover: README.md, "Security and limits" and the Docker paragraph.

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

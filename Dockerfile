# Dockerfile - build and run kmorphd, the kmorph HTTP service.
#
#   podman build --build-arg KMORPH_VERSION=$(cat VERSION) -t kmorph .
#   (or `make image`, which passes it)
#
# Stage 1 compiles with the Debian 12 packages the build needs, each named:
# the compiler and C library headers, make, pkg-config and the two
# libraries' -dev packages (the Makefile's NEEDED_HEADERS, cmocka aside:
# it is for the tests). `make install` stages the daemon and its web page.
# Stage 2 carries only those and the runtime libraries of the -dev
# packages; the daemon is its own health probe (kmorphd --healthcheck), so
# no HTTP client is installed.
FROM debian:12-slim AS build
RUN apt-get update \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
      gcc libc6-dev make pkg-config libcjson-dev libmicrohttpd-dev zlib1g-dev \
 && rm -rf /var/lib/apt/lists/*
WORKDIR /src
COPY . .
# The version label is the tree's VERSION: `make image` passes it, a
# different one is refused (a build without it, as compose's, leaves the
# label empty; kmorphd --version still says it).
ARG KMORPH_VERSION=
RUN test -z "$KMORPH_VERSION" || test "$KMORPH_VERSION" = "$(cat VERSION)" \
 || { echo "KMORPH_VERSION $KMORPH_VERSION is not VERSION $(cat VERSION)" >&2; exit 1; }
RUN make build \
 && make install PREFIX=/usr/local DESTDIR=/staging

FROM debian:12-slim
ARG KMORPH_VERSION=
LABEL org.opencontainers.image.title="kmorph" \
      org.opencontainers.image.description="HTTP service morphing planar curves by blending their curvature (Surazhsky & Elber)" \
      org.opencontainers.image.version="${KMORPH_VERSION}" \
      org.opencontainers.image.licenses="MIT" \
      org.opencontainers.image.base.name="docker.io/library/debian:12-slim"
RUN apt-get update \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
      libcjson1 libmicrohttpd12 zlib1g \
 && rm -rf /var/lib/apt/lists/* \
 && useradd --system --uid 10001 --no-create-home --shell /usr/sbin/nologin kmorph
# The daemon finds its page in share/kmorph/web beside its executable.
COPY --from=build /staging/usr/local/sbin/kmorphd /usr/local/sbin/kmorphd
COPY --from=build /staging/usr/local/share/kmorph/web /usr/local/share/kmorph/web
COPY --from=build /src/LICENSE /usr/local/share/doc/kmorph/LICENSE
# Listen on every interface inside the container; flags still override.
ENV KMORPH_BIND=0.0.0.0 \
    KMORPH_PORT=8080
USER kmorph
EXPOSE 8080
STOPSIGNAL SIGTERM
HEALTHCHECK --interval=10s --timeout=3s --start-period=5s --retries=3 \
  CMD /usr/local/sbin/kmorphd --healthcheck "http://127.0.0.1:${KMORPH_PORT}/healthz"
ENTRYPOINT ["/usr/local/sbin/kmorphd"]

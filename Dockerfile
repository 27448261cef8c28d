# Dockerfile - build and run kmorphd, the kmorph HTTP service.
#
# Stage 1 compiles with the same Debian 12 packages the Makefile's `deps`
# target installs for building (gcc make pkg-config libcjson-dev
# libmicrohttpd-dev); stage 2 carries only the binary, the runtime
# libraries of those packages and curl for the health check.
FROM debian:12-slim AS build
RUN apt-get update \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
      gcc make pkg-config libcjson-dev libmicrohttpd-dev \
 && rm -rf /var/lib/apt/lists/*
WORKDIR /src
COPY . .
RUN make build \
 && mkdir -p clients/web

FROM debian:12-slim
RUN apt-get update \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
      libcjson1 libmicrohttpd12 curl \
 && rm -rf /var/lib/apt/lists/* \
 && useradd --system --uid 10001 --no-create-home --shell /usr/sbin/nologin kmorph
COPY --from=build /src/build/kmorphd /usr/local/bin/kmorphd
COPY --from=build /src/clients/web /usr/share/kmorph/web
# Listen on every interface inside the container; flags still override.
ENV KMORPH_BIND=0.0.0.0 \
    KMORPH_PORT=8080 \
    KMORPH_WEB_ROOT=/usr/share/kmorph/web
USER kmorph
EXPOSE 8080
STOPSIGNAL SIGTERM
HEALTHCHECK --interval=10s --timeout=3s --start-period=5s --retries=3 \
  CMD curl -fsS "http://127.0.0.1:${KMORPH_PORT}/healthz" >/dev/null || exit 1
ENTRYPOINT ["/usr/local/bin/kmorphd"]

# One image for every boltwatch service; the command picks the service.
#   docker build -t boltwatch:0.1.0 .
#   docker run --rm boltwatch:0.1.0 --help

# The OPC UA models of `boltwatch serve opcua`, fetched at build time by the project's own
# fetch (services/opcua/nodeset_files.py: `npm pack` of the pinned node-opcua-nodesets, its
# sha512 checked, seven XML files extracted). A stage of its own: the image gets the files,
# not node or npm. fetch() fails the build on any error (without npm too).
FROM node:22-bookworm-slim AS opcua-nodesets
RUN apt-get update \
    && apt-get install -y --no-install-recommends python3 \
    && rm -rf /var/lib/apt/lists/*
WORKDIR /build
COPY services/opcua/nodeset_files.py services/opcua/
RUN BOLTWATCH_OPCUA_NODESETS=/opt/opcua-nodesets python3 -c \
    "from services.opcua.nodeset_files import fetch, nodeset_folder; fetch(nodeset_folder())"

FROM python:3.11-slim

WORKDIR /opt/boltwatch
COPY pyproject.toml README.md ./
COPY shared ./shared
COPY services ./services
RUN pip install --no-cache-dir . \
    && useradd --system --uid 10001 --home-dir /var/lib/boltwatch boltwatch \
    && mkdir -p /var/lib/boltwatch/recordings \
    && chown -R boltwatch /var/lib/boltwatch
COPY --from=opcua-nodesets /opt/opcua-nodesets /opt/boltwatch/opcua-nodesets

# Configuration is mounted at /etc/boltwatch (see docker-compose.yml).
ENV BOLTWATCH_LOG_FORMAT=json
# where nodeset_files.py finds the models (<folder>/<version>/), read-only for the services
ENV BOLTWATCH_OPCUA_NODESETS=/opt/boltwatch/opcua-nodesets
USER boltwatch
ENTRYPOINT ["boltwatch"]
CMD ["--help"]

# One image for every boltwatch service; the command picks the service.
#   docker build -t boltwatch:0.1.0 .
#   docker run --rm boltwatch:0.1.0 --help
FROM python:3.11-slim

WORKDIR /opt/boltwatch
COPY pyproject.toml README.md ./
COPY shared ./shared
COPY services ./services
RUN pip install --no-cache-dir . \
    && useradd --system --uid 10001 --home-dir /var/lib/boltwatch boltwatch \
    && mkdir -p /var/lib/boltwatch/recordings \
    && chown -R boltwatch /var/lib/boltwatch

# Configuration is mounted at /etc/boltwatch (see docker-compose.yml).
ENV BOLTWATCH_LOG_FORMAT=json
USER boltwatch
ENTRYPOINT ["boltwatch"]
CMD ["--help"]

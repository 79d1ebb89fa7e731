#!/usr/bin/env bash
# Make the line's certificates for zenoh mutual TLS (docs/how-to/compose-and-tls.md).
#
#   config/security/make-certs.sh OUT_DIR NAME...
#
# OUT_DIR gets ca.pem + ca.key (the line's CA: keep ca.key offline), then
# router.pem + router.key, and NAME.pem + NAME.key for each service NAME
# (the certificate's common name, which the router's access control matches:
# st1-acquisition, st1-predictor, line-recorder, ...). The router's
# certificate names localhost and 127.0.0.1; add the names services use to
# reach it with ROUTER_SAN="DNS:router.plant.local,IP:10.0.0.5".
# A plant of several lines shares one CA: ROUTER_NAME=line2-router makes
# line2-router.pem + .key instead of router.pem (its common name is what the
# other lines' access control names with --peer; docs/reference/access-control.md).
# An existing CA in OUT_DIR is reused, so services can be added later.
# Needs the openssl CLI (1.1.1 or 3.x). Keys are EC P-256, certificates last
# DAYS days (default 825). Private keys are written 0600 and never committed.
set -euo pipefail

if [[ $# -lt 1 ]]; then
    echo "usage: $0 OUT_DIR [NAME...]" >&2
    exit 2
fi
out=$1
shift
days=${DAYS:-825}
router_san="DNS:localhost,IP:127.0.0.1${ROUTER_SAN:+,$ROUTER_SAN}"
router_name=${ROUTER_NAME:-router}
if [[ ! $router_name =~ ^[A-Za-z0-9._-]+$ ]]; then
    echo "$0: ROUTER_NAME=$router_name: a certificate name is letters, digits, '.', '_' or '-'" >&2
    exit 2
fi
mkdir -p "$out"
umask 077

key() { openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out "$1" 2>/dev/null; }

if [[ ! -f "$out/ca.key" ]]; then
    key "$out/ca.key"
    openssl req -x509 -new -key "$out/ca.key" -days "$days" -subj "/CN=boltwatch line CA" \
        -addext "basicConstraints=critical,CA:TRUE" \
        -addext "keyUsage=critical,keyCertSign,cRLSign" \
        -out "$out/ca.pem" 2>/dev/null
fi

# sign NAME EXTENSIONS: NAME.key + NAME.pem signed by the CA
sign() {
    local name=$1 extensions=$2
    key "$out/$name.key"
    openssl req -new -key "$out/$name.key" -subj "/CN=$name" -out "$out/$name.csr" 2>/dev/null
    openssl x509 -req -in "$out/$name.csr" -CA "$out/ca.pem" -CAkey "$out/ca.key" \
        -CAcreateserial -days "$days" -extfile <(printf '%s\n' "$extensions") \
        -out "$out/$name.pem" 2>/dev/null
    rm -f "$out/$name.csr"
    chmod 644 "$out/$name.pem"
}

common="basicConstraints=critical,CA:FALSE
keyUsage=critical,digitalSignature"
sign "$router_name" "$common
extendedKeyUsage=serverAuth,clientAuth
subjectAltName=$router_san"
for name in "$@"; do
    if [[ ! $name =~ ^[A-Za-z0-9._-]+$ ]]; then
        echo "$0: $name: a certificate name is letters, digits, '.', '_' or '-'" >&2
        exit 2
    fi
    sign "$name" "$common
extendedKeyUsage=clientAuth"
done
chmod 644 "$out/ca.pem"
echo "certificates in $out: ca.pem $router_name.pem $(printf '%s.pem ' "$@")"

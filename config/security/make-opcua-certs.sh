#!/usr/bin/env bash
# Make the RSA certificates of `boltwatch serve opcua` (docs/how-to/opcua.md, "Security").
#
#   config/security/make-opcua-certs.sh OUT_DIR [CLIENT...]
#
# OPC UA's Basic256Sha256 signs and encrypts with RSA keys (the zenoh certificates of
# make-certs.sh are EC: they cannot serve here). OUT_DIR gets
#   server.pem + server.key   the server's application instance certificate, self-signed
#                             (its clients trust it directly); its subjectAltName names
#                             the application URI OPCUA_URI (default urn:boltwatch:opcua),
#                             localhost, 127.0.0.1 and OPCUA_SAN ("DNS:opcua,DNS:line1.plant")
#   ca.pem + ca.key           the CA of the clients (keep ca.key offline): the server's
#                             --trusted-clients folder holds ca.pem, so a client whose
#                             certificate it signed gets in, and no other
#   CLIENT.pem + CLIENT.key   for each CLIENT (an MES, a SCADA), signed by the CA; its
#                             application URI is urn:boltwatch:opcua-client:CLIENT (the
#                             client must say that URI when it connects)
# A client that makes its own certificate (UaExpert, an MES) is trusted by copying its
# certificate into the --trusted-clients folder instead. An existing CA is reused, so
# clients can be added later, and so are an existing server.pem + server.key (its
# clients trust that certificate): delete them for a new one (another OPCUA_SAN).
# Needs the openssl CLI (1.1.1 or 3.x). Keys are RSA 2048, certificates last DAYS days
# (default 825). Private keys are written 0600 and never committed.
set -euo pipefail

if [[ $# -lt 1 ]]; then
    echo "usage: $0 OUT_DIR [CLIENT...]" >&2
    exit 2
fi
out=$1
shift
days=${DAYS:-825}
uri=${OPCUA_URI:-urn:boltwatch:opcua}
server_san="URI:$uri,DNS:localhost,IP:127.0.0.1${OPCUA_SAN:+,$OPCUA_SAN}"
mkdir -p "$out"
umask 077

key() { openssl genpkey -algorithm RSA -pkeyopt rsa_keygen_bits:2048 -out "$1" 2>/dev/null; }

# the key usages and extended key usage OPC UA asks of an application instance certificate
usage="basicConstraints=critical,CA:FALSE
keyUsage=critical,digitalSignature,nonRepudiation,keyEncipherment,dataEncipherment"

# request NAME: an openssl req config whose v3 section is the extensions on stdin
request() { printf '[req]\ndistinguished_name = dn\n[dn]\n[v3]\n%s\n' "$(cat)" >"$out/$1.cnf"; }

if [[ ! -f "$out/ca.key" ]]; then
    key "$out/ca.key"
    openssl req -x509 -new -key "$out/ca.key" -days "$days" -subj "/CN=boltwatch OPC UA clients CA" \
        -addext "basicConstraints=critical,CA:TRUE" \
        -addext "keyUsage=critical,keyCertSign,cRLSign" \
        -out "$out/ca.pem" 2>/dev/null
fi

if [[ ! -f "$out/server.pem" || ! -f "$out/server.key" ]]; then
    key "$out/server.key"
    request server <<<"$usage
extendedKeyUsage=serverAuth,clientAuth
subjectAltName=$server_san"
    openssl req -x509 -new -key "$out/server.key" -days "$days" -subj "/CN=boltwatch opcua" \
        -extensions v3 -config "$out/server.cnf" -out "$out/server.pem" 2>/dev/null
    rm -f "$out/server.cnf"
fi

for name in "$@"; do
    if [[ ! $name =~ ^[A-Za-z0-9._-]+$ ]]; then
        echo "$0: $name: a client name is letters, digits, '.', '_' or '-'" >&2
        exit 2
    fi
    key "$out/$name.key"
    openssl req -new -key "$out/$name.key" -subj "/CN=$name" -out "$out/$name.csr" 2>/dev/null
    openssl x509 -req -in "$out/$name.csr" -CA "$out/ca.pem" -CAkey "$out/ca.key" \
        -CAcreateserial -days "$days" \
        -extfile <(printf '%s\n' "$usage" "extendedKeyUsage=clientAuth" \
            "subjectAltName=URI:urn:boltwatch:opcua-client:$name,DNS:localhost") \
        -out "$out/$name.pem" 2>/dev/null
    rm -f "$out/$name.csr"
    chmod 644 "$out/$name.pem"
done
chmod 644 "$out/ca.pem" "$out/server.pem"
echo "OPC UA certificates in $out: server.pem ca.pem $(printf '%s.pem ' "$@")"

#!/usr/bin/env bash
# Certificates and access control for docker-compose.tls.yml (docs/how-to/compose-and-tls.md).
#
#   config/security/make-compose-certs.sh OUT_DIR [STATION...]      (default stations: st1 st2)
#   BOLTWATCH_CERTS=OUT_DIR BOLTWATCH_RECORDINGS=$PWD/recordings \
#       docker compose -f docker-compose.yml -f docker-compose.tls.yml up --build
#
# Every container gets its own identity: OUT_DIR/<name>/ holds ca.pem (the line's
# CA), identity.pem (a certificate whose common name is <name>) and identity.key,
# and is mounted read-only at /etc/boltwatch-identity. It makes only the identities
# the compose files use (and the operator's); the names are the access control's
# subjects (services/router/access_control.py):
#   router                                   the router (server certificate, names "router")
#                                            + acl.json5, the access control for STATION...
#   line-recorder, line-viewer, line-monitor the line's recorder, the live viewer, the operator
#   line-opcua                               the line's OPC UA server (its zenoh identity)
#   <st>-acquisition, <st>-rig               for each station (the acquisition holds the
#                                            station's predictor: placement "edge")
# EXTRA_IDENTITIES="st1-predictor ..." makes more, e.g. for a line predictor
# (placement "line": docker-compose.tls.yml says how to add one).
# The OPC UA server (the opcua service, with or without TLS) gets RSA files of
# config/security/make-opcua-certs.sh: OUT_DIR/opcua-server/ holds server.pem,
# server.key, trusted/ca.pem (the CA of its clients) and opcua-users.toml (its users,
# `boltwatch opcua-user`), mounted read-only at /etc/boltwatch-opcua;
# OUT_DIR/opcua-<client>/ holds a client's identity.pem, identity.key, the server.pem
# it trusts and the password of its user <client> (made here, 0600), for each of
# OPCUA_CLIENTS (default "mes"); OUT_DIR/opcua-ca/ keeps the clients' CA key (never
# mounted). OPCUA_SAN adds the names the plant reaches the server by
# ("DNS:line1.plant.local") to "opcua". When the script runs again the server's
# certificate (its clients trust it) and each client's password are kept.
# OUT_DIR/line-ca/ is config/security/make-certs.sh's folder: the CA's key (ca.key) is
# there and is never mounted; keep it offline. Running again reuses the CA and
# re-issues every identity. Keys are 0600; the containers run as uid 10001
# (Dockerfile), so as root the identities are given to that uid (BOLTWATCH_UID);
# otherwise the script prints the chown to run. Nothing here is ever committed.
set -euo pipefail

if [[ $# -lt 1 ]]; then
    echo "usage: $0 OUT_DIR [STATION...]   (default stations: st1 st2)" >&2
    exit 2
fi
out=$1
shift
stations=("$@")
if [[ ${#stations[@]} -eq 0 ]]; then
    stations=(st1 st2)
fi
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/../.." && pwd)
owner_uid=${BOLTWATCH_UID:-10001}

names=(line-recorder line-viewer line-monitor line-opcua)
for station in "${stations[@]}"; do
    names+=("$station-acquisition" "$station-rig")
done
if [[ -n ${EXTRA_IDENTITIES:-} ]]; then
    read -r -a extra <<<"$EXTRA_IDENTITIES"
    names+=("${extra[@]}")
fi

# The services reach the router as "router" (the compose service name).
ROUTER_SAN="DNS:router${ROUTER_SAN:+,$ROUTER_SAN}" "$here/make-certs.sh" "$out/line-ca" "${names[@]}" >/dev/null
umask 077

# identity NAME SOURCE_STEM: OUT_DIR/NAME/{ca.pem,identity.pem,identity.key}
identity() {
    local name=$1 stem=$2 folder="$out/$1"
    mkdir -p "$folder"
    chmod 755 "$folder"
    install -m 644 "$out/line-ca/ca.pem" "$folder/ca.pem"
    install -m 644 "$out/line-ca/$stem.pem" "$folder/identity.pem"
    install -m 600 "$out/line-ca/$stem.key" "$folder/identity.key"
    rm -f "$out/line-ca/$stem.key"  # one copy of each key: in its own identity folder
}

identity router router
# the generator reads the channel table (shared/contract/channels.py), which needs the project's
# packages: the checkout's .venv (make run makes it) unless PYTHON names another
python=${PYTHON:-python3}
[ -n "${PYTHON:-}" ] || [ ! -x "$repo/.venv/bin/python" ] || python="$repo/.venv/bin/python"
PYTHONPATH="$repo${PYTHONPATH:+:$PYTHONPATH}" "$python" -m services.router.access_control \
    "${stations[@]}" >"$out/router/acl.json5.new"
mv "$out/router/acl.json5.new" "$out/router/acl.json5"
chmod 644 "$out/router/acl.json5"
for name in "${names[@]}"; do
    identity "$name" "$name"
done

# The OPC UA server's RSA files (Basic256Sha256 needs RSA; the identities above are EC).
read -r -a opcua_clients <<<"${OPCUA_CLIENTS:-mes}"
server="$out/opcua-server"
if [[ -f "$server/server.pem" && -f "$server/server.key" ]]; then
    mkdir -p "$out/opcua-ca"
    cp -p "$server/server.pem" "$server/server.key" "$out/opcua-ca/"
fi
OPCUA_SAN="DNS:opcua${OPCUA_SAN:+,$OPCUA_SAN}" "$here/make-opcua-certs.sh" "$out/opcua-ca" \
    "${opcua_clients[@]}" >/dev/null
mkdir -p "$server/trusted"
chmod 755 "$server" "$server/trusted"
install -m 644 "$out/opcua-ca/ca.pem" "$server/trusted/ca.pem"
install -m 644 "$out/opcua-ca/server.pem" "$server/server.pem"
install -m 600 "$out/opcua-ca/server.key" "$server/server.key"
rm -f "$out/opcua-ca/server.key"
for name in "${opcua_clients[@]}"; do
    client="$out/opcua-$name"
    mkdir -p "$client"
    install -m 644 "$server/server.pem" "$client/server.pem"
    install -m 644 "$out/opcua-ca/$name.pem" "$client/identity.pem"
    install -m 600 "$out/opcua-ca/$name.key" "$client/identity.key"
    rm -f "$out/opcua-ca/$name.key"
done
# Its users (--users): one per client, with a password made here, given once to the
# user file's command (which keeps only a salted hash) and kept in the client's folder.
# A client already in the users file with its password kept is left as it is; any other
# gets a new password (a users file made again names every client again).
users="$server/opcua-users.toml"
opcua_user() {
    PYTHONPATH="$repo${PYTHONPATH:+:$PYTHONPATH}" "$python" -m services.cli opcua-user "$@"
}
for name in "${opcua_clients[@]}"; do
    password_file="$out/opcua-$name/password"
    if [[ -f $password_file && -f $users ]] \
        && opcua_user list --users "$users" | cut -f1 | grep -qxF -- "$name"; then
        continue
    fi
    password=$(openssl rand -base64 24)
    printf '%s\n' "$password" | opcua_user add "$name" --users "$users" >/dev/null
    printf '%s\n' "$password" >"$password_file"
    chmod 600 "$password_file"
done

folders=(router "${names[@]}" opcua-server)
if [[ $(id -u) -eq 0 ]]; then
    for name in "${folders[@]}"; do
        chown -R "$owner_uid" "$out/$name"
    done
    owned="owned by uid $owner_uid (the containers' user)"
else
    owned="keys 0600: the containers run as uid $owner_uid, so run
  sudo chown -R $owner_uid ${folders[*]/#/$out/}"
fi
echo "identities in $out: ${folders[*]} ($owned); the CA keys stay in $out/line-ca and \
$out/opcua-ca; OPC UA clients: ${opcua_clients[*]/#/$out/opcua-}"

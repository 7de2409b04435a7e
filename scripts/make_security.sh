#!/usr/bin/env bash
# Makes the files DDS Security needs (launch_yaml/README.md, "DDS Security"), with the openssl
# command-line tool only:
#
#   scripts/make_security.sh OUT_DIR [--subscribe-only NAME]... IDENTITY...
#
# OUT_DIR then holds
#   ca.cert.pem, ca.key.pem      a certificate authority (EC prime256v1, self-signed); keep
#                                ca.key.pem away from the machines that only run participants
#   governance.xml, .smime       the domain rules, signed by the CA: every domain (0..230, the
#                                most Cyclone DDS reads) needs authentication; discovery,
#                                liveliness and all messages (data and metadata) are encrypted
#                                submessage by submessage; every topic needs read and write
#                                permission. Whole RTPS messages are not wrapped once more
#                                (rtps_protection_kind NONE): Fast DDS 2.9.1 reserves room for
#                                its statistics submessage in the plain message only, and a
#                                full message that grew when wrapped aborted the process
#                                (add_statistics_submessage's assertion)
#   NAME.key.pem, NAME.cert.pem  one identity per NAME: its key and its certificate (subject
#                                CN=NAME, signed by the CA)
#   NAME.permissions.xml, .smime what NAME may do, signed by the CA: publish and subscribe to
#                                every topic of every domain; with --subscribe-only NAME,
#                                subscribe only, but for its process's health: its statuses
#                                (rt/diagnostics) and its clock's answers to probes
#                                (rt/mocap/clock/reply), which every process of mocap_launch
#                                publishes. Anything else is denied.
#
# A launch file uses it with `dds: {security: {directory: OUT_DIR, identity: NAME}}`.
#
# Running it again on the same OUT_DIR keeps the CA and the identities' keys and certificates
# (so new identities join the same CA) and writes governance and permissions anew. Identities
# made with another OUT_DIR belong to another CA: participants of the two cannot talk.
set -euo pipefail

usage() {
  echo "usage: $0 OUT_DIR [--subscribe-only NAME]... IDENTITY..." >&2
  echo "  makes a CA, signed governance, and a key, certificate and signed permissions per" >&2
  echo "  identity (NAME: letters, digits, '_' and '-')" >&2
  exit 2
}

fail() {
  echo "make_security: $*" >&2
  exit 1
}

[ $# -ge 1 ] || usage
case "$1" in -h | --help) usage ;; esac
out=$1
shift
publishers=()
subscribers=()
while [ $# -gt 0 ]; do
  case "$1" in
    --subscribe-only)
      [ $# -ge 2 ] || fail "--subscribe-only needs a NAME"
      subscribers+=("$2")
      shift 2
      ;;
    -*) fail "unknown option $1" ;;
    *)
      publishers+=("$1")
      shift
      ;;
  esac
done
all=("${publishers[@]}" "${subscribers[@]}")
[ ${#all[@]} -gt 0 ] || fail "no IDENTITY given"
for name in "${all[@]}"; do
  [[ "$name" =~ ^[A-Za-z0-9_-]+$ ]] ||
    fail "identity '$name' must use letters, digits, '_' and '-'"
  [ "$name" != ca ] || fail "identity 'ca' is reserved for the certificate authority"
done
duplicates=$(printf '%s\n' "${all[@]}" | sort | uniq -d)
[ -z "$duplicates" ] || fail "identity given twice: $duplicates"
command -v openssl > /dev/null || fail "openssl not found (Debian package openssl)"

mkdir -p "$out" || fail "cannot create $out"
cd "$out"
umask 077  # keys are for their owner only

# Runs openssl quietly; on failure shows what it said and names the step.
run() {
  local what=$1
  shift
  local output
  if ! output=$(openssl "$@" 2>&1); then
    echo "$output" >&2
    fail "$what failed (openssl $1)"
  fi
}

new_key() { run "key $1" genpkey -algorithm EC -pkeyopt ec_paramgen_curve:prime256v1 -out "$1"; }

sign() {  # FILE.xml -> FILE.smime, S/MIME signed by the CA as Fast DDS reads it (text/plain)
  run "signing $1.xml" smime -sign -text -in "$1.xml" -out "$1.smime" -signer ca.cert.pem \
    -inkey ca.key.pem
}

if [ ! -f ca.key.pem ] || [ ! -f ca.cert.pem ]; then
  if [ -f ca.cert.pem ] || [ -f ca.key.pem ]; then
    fail "$out has only one of ca.key.pem and ca.cert.pem; remove it or use another OUT_DIR"
  fi
  new_key ca.key.pem
  run "CA certificate" req -new -x509 -sha256 -days 3650 -key ca.key.pem -out ca.cert.pem \
    -subj "/CN=mocap-graph DDS CA $(date -u +%Y%m%dT%H%M%S) $RANDOM"
  echo "make_security: new CA in $out"
fi

for name in "${all[@]}"; do
  if [ ! -f "$name.cert.pem" ] || [ ! -f "$name.key.pem" ] ||
    ! openssl verify -CAfile ca.cert.pem "$name.cert.pem" > /dev/null 2>&1; then
    new_key "$name.key.pem"
    run "request for $name" req -new -sha256 -key "$name.key.pem" -subj "/CN=$name" \
      -out "$name.csr.pem"
    run "certificate of $name" x509 -req -sha256 -days 3650 -in "$name.csr.pem" \
      -CA ca.cert.pem -CAkey ca.key.pem -CAcreateserial -CAserial ca.srl -out "$name.cert.pem"
    rm -f "$name.csr.pem"
  fi
done

cat > governance.xml << 'EOF'
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains>
        <id_range><min>0</min><max>230</max></id_range>
      </domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>NONE</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
EOF
sign governance

not_before=$(date -u -d '1 day ago' +%Y-%m-%dT%H:%M:%S)
not_after=$(date -u -d '10 years' +%Y-%m-%dT%H:%M:%S)
permissions() {  # NAME RULES
  cat > "$1.permissions.xml" << EOF
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
    <grant name="$1">
      <subject_name>CN=$1</subject_name>
      <validity>
        <not_before>$not_before</not_before>
        <not_after>$not_after</not_after>
      </validity>
      <allow_rule>
        <domains>
          <id_range><min>0</min><max>230</max></id_range>
        </domains>
$2
      </allow_rule>
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
EOF
  sign "$1.permissions"
}
publish='        <publish><topics><topic>*</topic></topics></publish>'
subscribe='        <subscribe><topics><topic>*</topic></topics></subscribe>'
health='        <publish><topics><topic>rt/diagnostics</topic><topic>rt/mocap/clock/reply</topic></topics></publish>'
for name in "${publishers[@]}"; do permissions "$name" "$publish"$'\n'"$subscribe"; done
for name in "${subscribers[@]}"; do permissions "$name" "$health"$'\n'"$subscribe"; done
chmod 644 ./*.cert.pem ./*.xml ./*.smime

made="${publishers[*]}"
if [ ${#subscribers[@]} -gt 0 ]; then
  made="${made:+$made, }${subscribers[*]} (subscribe only)"
fi
echo "make_security: $out: identities $made"

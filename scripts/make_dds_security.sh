#!/usr/bin/env bash
# Creates the files of the `secure` DDS profile (config/dds/profiles.xml) with
# openssl: a test certificate authority, one certificate and key per process
# (the DDS participant name), a governance document (authentication required,
# discovery, liveliness and data encrypted) and a permissions document that
# lets each of those participants publish and subscribe on the domains given;
# both documents signed (S/MIME) by the CA. Point dds.security_dir (or
# PIXYSLAM_DDS_SECURITY_DIR) at OUT_DIR.
#   scripts/make_dds_security.sh OUT_DIR [--domains 0-232] [--days 365] [NAME ...]
# Default names: every pixyslam process and tool. Keep ca.key.pem off the robot.
set -euo pipefail

case ${1:-} in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
usage() { echo "usage: $0 OUT_DIR [--domains MIN-MAX] [--days N] [NAME ...] (--help: more)" >&2; exit 2; }
[[ $# -ge 1 && $1 != -* ]] || usage
out=$1; shift
domains=0-232 days=365 names=()
while [[ $# -gt 0 ]]; do
  case $1 in
    --domains) domains=${2:?}; shift 2 ;;
    --days) days=${2:?}; shift 2 ;;
    -*) usage ;;
    *) names+=("$1"); shift ;;
  esac
done
if [[ ${#names[@]} -eq 0 ]]; then
  names=(encoder_bridge pixy_bridge slam_estimator map_optimizer logger robot_sim sim_evaluator map_view
         pixyslam_play pixyslam_spy pixyslam_launch foxglove_bridge fleet_map dataset_bridge)
fi
[[ $domains =~ ^([0-9]+)-([0-9]+)$ ]] || { echo "--domains must be MIN-MAX, got '$domains'" >&2; exit 2; }
domain_min=${BASH_REMATCH[1]} domain_max=${BASH_REMATCH[2]}
command -v openssl >/dev/null || { echo "openssl is not installed (apt-get install openssl)" >&2; exit 1; }

mkdir -p "$out"
cd "$out"
umask 077
subject() { echo "/C=ES/O=pixyslam/CN=$1"; }
# DDS Security wants the subject as in the certificate: "CN=..., O=..., C=...".
subject_rfc() { echo "CN=$1, O=pixyslam, C=ES"; }

# The CA: identity and permissions CA in one (EC P-256, as the DDS spec's examples).
openssl ecparam -name prime256v1 -genkey -noout -out ca.key.pem
openssl req -x509 -new -key ca.key.pem -out ca.cert.pem -days "$days" -subj "$(subject pixyslam_test_ca)" \
  -addext basicConstraints=critical,CA:TRUE -addext keyUsage=critical,keyCertSign,cRLSign,digitalSignature 2>/dev/null

for name in "${names[@]}"; do
  [[ $name =~ ^[A-Za-z0-9_.-]+$ ]] || { echo "bad participant name '$name'" >&2; exit 2; }
  openssl ecparam -name prime256v1 -genkey -noout -out "$name.key.pem"
  openssl req -new -key "$name.key.pem" -out "$name.csr.pem" -subj "$(subject "$name")"
  openssl x509 -req -in "$name.csr.pem" -CA ca.cert.pem -CAkey ca.key.pem -CAcreateserial \
    -out "$name.cert.pem" -days "$days" 2>/dev/null
  rm -f "$name.csr.pem"
done
rm -f ca.cert.srl

not_before=$(date -u +%Y-%m-%dT%H:%M:%S)
not_after=$(date -u -d "+$days days" +%Y-%m-%dT%H:%M:%S)

cat > governance.xml <<EOF
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance">
  <domain_access_rules>
    <domain_rule>
      <domains><id_range><min>$domain_min</min><max>$domain_max</max></id_range></domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>ENCRYPT</rtps_protection_kind>
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

{
  echo '<?xml version="1.0" encoding="UTF-8"?>'
  echo '<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance">'
  echo '  <permissions>'
  for name in "${names[@]}"; do
    cat <<EOF
    <grant name="$name">
      <subject_name>$(subject_rfc "$name")</subject_name>
      <validity><not_before>$not_before</not_before><not_after>$not_after</not_after></validity>
      <allow_rule>
        <domains><id_range><min>$domain_min</min><max>$domain_max</max></id_range></domains>
        <publish><topics><topic>*</topic></topics></publish>
        <subscribe><topics><topic>*</topic></topics></subscribe>
      </allow_rule>
      <default>DENY</default>
    </grant>
EOF
  done
  echo '  </permissions>'
  echo '</dds>'
} > permissions.xml

for doc in governance permissions; do
  openssl smime -sign -in "$doc.xml" -text -out "$doc.p7s" -signer ca.cert.pem -inkey ca.key.pem
done
chmod 644 ./*.cert.pem ./*.xml ./*.p7s
echo "make_dds_security: CA, ${#names[@]} participant certificates, governance.p7s, permissions.p7s in $out" \
     "(domains $domains, valid $days days)"

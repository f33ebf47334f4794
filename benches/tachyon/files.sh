# Sourced by run.sh and check.sh (after N and SIZE are set, in benches/tachyon/): the
# settings both share, and the two scene files for N written once into DIR.
DIR=${DIR:-/tmp/gtsphere-tachyon}
FORM=${FORM:-proto}
GTS=${GTSPHERE:-$(pwd)/../../target/release/gtsphere}
TACHYON=${TACHYON:-tachyon}
command -v "$TACHYON" > /dev/null || {
    echo "tachyon not found: apt-get update && apt-get install -y tachyon" >&2
    exit 1
}
[ -x "$GTS" ] || (cd ../.. && cargo build --release -p gtsphere-cli)
case $FORM in
    proto) WRL=$DIR/spheres-$N.wrl PLAIN= ;;
    plain) WRL=$DIR/spheres-$N-plain.wrl PLAIN=--plain ;;
    *) echo "FORM must be proto or plain" >&2 && exit 2 ;;
esac
DAT=$DIR/spheres-$N-$SIZE.dat
mkdir -p "$DIR"
if [ ! -s "$WRL" ] || [ ! -s "$DAT" ]; then
    echo "writing $WRL and $DAT" >&2
    # shellcheck disable=SC2086
    python3 gen.py "$N" "$WRL.part" "$DAT.part" --size "$SIZE" $PLAIN
    mv "$WRL.part" "$WRL"
    mv "$DAT.part" "$DAT"
fi

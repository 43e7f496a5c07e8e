# Shared by the tests/cli/check_*.sh scripts (sourced, after they set RC and
# WORK): DATA (tests/data, absolute), a fresh work directory to run in, and
# the helpers below.
DATA=$(cd "$(dirname "$0")/../data" && pwd)
rm -rf "$WORK"
mkdir -p "$WORK"
cd "$WORK"

fail() {
    echo "FAIL: $*" >&2
    exit 1
}

# run EXPECTED_STATUS MESSAGE_PART cmd...: the status and a stderr line
# containing MESSAGE_PART ("" for none); stdout is left in out.txt.
run() {
    want=$1
    msg=$2
    shift 2
    set +e
    "$@" >out.txt 2>err.txt
    got=$?
    set -e
    [ "$got" -eq "$want" ] || { cat err.txt >&2; fail "'$*' exited $got, expected $want"; }
    if [ -n "$msg" ] && ! grep -q -- "$msg" err.txt; then
        cat err.txt >&2
        fail "'$*': stderr lacks '$msg'"
    fi
}

# 0 when the program was built with libpng.
has_png() {
    "$RC" help | grep -q "Images: PNG"
}

# is_png FILE: fails unless FILE starts with the PNG signature.
is_png() {
    [ "$(head -c 4 "$1" | od -An -c | tr -d ' ')" = "211PNG" ] || fail "$1 is not a PNG"
}

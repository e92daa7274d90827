# Shared by the tests/cli_*.sh scripts (not a test itself): source it first. Sets $tool,
# $shared and a scratch folder $tmp (removed on exit), and gives small assertion helpers that
# count passes and failures; end a script with `cli_finish`.
set -u
tool="${VF_TOOL:?}"
shared="${VF_SHARED_DIR:?}"
tmp=$(mktemp -d /tmp/vfcli-XXXXXX)
trap 'rm -rf "$tmp"' EXIT
passed=0 failed=0
ok() { passed=$((passed + 1)); }
bad() { failed=$((failed + 1)); echo "FAIL: $*" >&2; }
# expect CODE DESCRIPTION -- command...   (stdout in $tmp/out, stderr in $tmp/err)
expect() {
  local code=$1 what=$2; shift 3
  "$@" >"$tmp/out" 2>"$tmp/err"
  local got=$?
  if [ "$got" -eq "$code" ]; then ok; else bad "$what: exit $got, wanted $code: $(head -c 300 "$tmp/err")"; fi
}
# One clear line: stderr has exactly one line, naming what is wrong.
one_line_naming() {
  local what=$1 needle=$2
  if [ "$(grep -c . "$tmp/err")" -eq 1 ] && grep -q -- "$needle" "$tmp/err"; then ok
  else bad "$what: wanted one line naming '$needle', got: $(cat "$tmp/err")"; fi
}
# json_check DESCRIPTION PYTHON-EXPRESSION-ON-d  (d = the JSON document on stdout)
json_check() {
  python3 -c "import json,sys; d=json.load(open(sys.argv[1])); sys.exit(0 if ($2) else 1)" "$tmp/out" \
    && ok || bad "$1: $(head -c 400 "$tmp/out")"
}
# help_works COMMAND...: each prints its usage with --help and exits 0
help_works() {
  for cmd in "$@"; do
    expect 0 "$cmd --help" -- "$tool" "$cmd" --help
    grep -q "usage: vfcapture $cmd" "$tmp/out" && ok || bad "$cmd --help prints its usage"
  done
}
cli_finish() {
  echo "$passed passed, $failed failed"
  [ "$failed" -eq 0 ]
}

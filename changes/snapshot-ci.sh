# Snapshot tests (insta): CI must fail on an unreviewed snapshot change, never accept it.
# With CI=true insta fails on a mismatch and writes no .snap; make sure nothing overrides
# that, and that no pending snapshot is left in the tree after the tests.
export CI=true
unset INSTA_UPDATE INSTA_FORCE_PASS
# (after `cargo test --locked`:)
if find . -path ./target -prune -o \( -name '*.snap.new' -o -name '*.pending-snap' \) -print | grep -q .; then
  echo "error: unreviewed insta snapshots (review with cargo insta review):"
  find . -path ./target -prune -o \( -name '*.snap.new' -o -name '*.pending-snap' \) -print
  exit 1
fi

#!/bin/sh
# the real fem-node, plus a grandchild that outlives it
(sleep 776 &)
exec "$(cd "$(dirname "$0")/../../.." && pwd)/target/release/fem-node" "$@"

#!/bin/bash
# The cost of a wire value's trip through one JSON socket: JsonSocketSession::on_wire's inclusive
# instructions (the offer, the flush or the one-lock path, the push's head and the socket's enqueue and
# wake; the value's JSON rendering once per value, by whichever socket comes first) per call, from each
# dump of callgrind-rate.sh. Usage: on-wire-cost.sh DIR... (each /tmp/touch56-cg/<name>, dumps 1..4 =
# r10a r10b r100a r100b).
for dir in "$@"; do
  for i in 1 2 3 4; do
    d=$dir/gw.out.$i
    [ -f "$d" ] || continue
    tag=$(echo r10a r10b r100a r100b | cut -d' ' -f$i)
    incl=$(callgrind_annotate --inclusive=yes --threshold=100 "$d" 2>/dev/null | grep -m1 'JsonSocketSession::on_wire(' | awk '{gsub(",", "", $1); print $1}')
    calls=$(python3 bench/callgrind_calls.py "$d" "$(grep -m1 -o 'rr::server::gateway::JsonSocketSession::on_wire([^)]*)' "$d")" | awk '{print $NF}')
    python3 -c "import sys; i, c = int(sys.argv[1]), int(sys.argv[2]); print('%s %s on_wire: %d calls, %d instructions inclusive, %.0f per call' % (sys.argv[3], sys.argv[4], c, i, i / c if c else 0))" "$incl" "$calls" "$(basename $dir)" "$tag"
  done
done

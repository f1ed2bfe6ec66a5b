# What bench/density.sh and bench/pipeline.sh share, sourced with their arguments ([TERRAPOLIS_BIN]):
# sets bin, threads (THREADS, default 2) and tmp (a new folder removed at exit), and defines
# median (of the numbers on stdin, the mean of the middle two for an even count).
# shellcheck shell=bash disable=SC2034  # the variables are for the scripts that source this file
bin=${1:-build/src/cli/terrapolis}
threads=${THREADS:-2}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

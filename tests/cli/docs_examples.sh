# Every tested example of docs/*.md runs as written and prints what the page shows (docs_examples.py).
set -euo pipefail
exec /usr/bin/python3 "$3/tests/cli/docs_examples.py" "$1" "$3"

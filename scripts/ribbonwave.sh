#!/usr/bin/env bash
# Launch ribbonwave (arguments as for the ribbonwave command), after scripts/setup.sh.
# Without a display it runs under Xvfb, which is useful with --screenshot OUT.png.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bash "$root/scripts/setup.sh"
if [[ -z "${DISPLAY:-}" && -z "${WAYLAND_DISPLAY:-}" ]]; then
  echo "ribbonwave.sh: no display; running under xvfb-run" >&2
  exec xvfb-run -a -s "-screen 0 1600x1000x24" "$root/.venv/bin/ribbonwave" "$@"
fi
exec "$root/.venv/bin/ribbonwave" "$@"

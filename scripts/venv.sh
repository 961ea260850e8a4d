# Sourced by scripts/setup.sh and scripts/setup-ros.sh: `install_into VENV REQUIREMENT...`
# creates the venv VENV (if needed, with pip, so that users can add packages the usual way) and
# installs the requirements into it with uv, which the venv's pip brings from PyPI first.
# Why uv: on a fresh clone pip took 49 s to install the development tools into a new .venv
# (resolving and unpacking on one core, wheels from its cache), uv 5 s from its cache (8 s
# downloading everything); same versions. Where uv cannot be had (no wheel for the platform),
# pip does the install as before.
install_into() {
  local venv=$1
  shift
  if [ ! -x "$venv/bin/python" ]; then
    "${PYTHON:-python3}" -m venv "$venv"
  fi
  if [ -x "$venv/bin/uv" ] || "$venv/bin/python" -m pip install --quiet "uv>=0.5" 2>/dev/null; then
    "$venv/bin/uv" pip install --quiet --compile-bytecode --python "$venv/bin/python" "$@"
  else
    "$venv/bin/python" -m pip install --quiet --upgrade pip
    "$venv/bin/python" -m pip install --quiet "$@"
  fi
}

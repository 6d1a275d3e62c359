"""A read-only install (system-wide, in a container, or for a user without
a writable HOME): numba caches the kernels in a writable folder instead of
refusing to import them."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def read_only(folder, command, env):
    """Run ``command`` in ``folder``'s parent with ``folder`` read-only: a
    read-only bind mount in a mount namespace of its own (root ignores
    permissions), else permissions."""
    if os.geteuid() != 0:
        for path in [folder, *folder.rglob("*")]:
            path.chmod(path.stat().st_mode & ~0o222)
        return subprocess.run(command, env=env, capture_output=True, text=True, timeout=300,
                              cwd=folder.parent)
    if shutil.which("unshare") is None:
        pytest.skip("running as root without unshare: no way to make a folder read-only")
    script = 'mount --bind "$1" "$1" && mount -o remount,bind,ro "$1" "$1" && shift && exec "$@"'
    done = subprocess.run(["unshare", "-m", "sh", "-c", script, "sh", str(folder), *command],
                          env=env, capture_output=True, text=True, timeout=300,
                          cwd=folder.parent)
    if "mount:" in done.stderr and done.returncode != 0:
        pytest.skip(f"no read-only bind mount here: {done.stderr.strip()}")
    return done


@pytest.fixture
def installed(tmp_path):
    """A copy of the package (no compiled caches) and an environment whose
    HOME cannot be written."""
    site = tmp_path / "site"
    shutil.copytree(ROOT / "meshwear", site / "meshwear",
                    ignore=shutil.ignore_patterns("__pycache__"))
    temp = tmp_path / "tmp"
    temp.mkdir()
    env = {k: v for k, v in os.environ.items()
           if k not in ("NUMBA_CACHE_DIR", "XDG_CACHE_HOME", "PYTHONPATH")}
    (site / "home").mkdir()         # read-only with the package
    env.update(PYTHONPATH=str(site), HOME=str(site / "home"), TMPDIR=str(temp))
    return site, temp, env


def test_a_read_only_package_caches_its_kernels_elsewhere(installed):
    site, temp, env = installed
    probe = ("import os, meshwear, meshwear.kernels.loop, meshwear.surfaces.active, "
             "meshwear.cli; print(meshwear.__file__); print(os.environ['NUMBA_CACHE_DIR'])")
    done = read_only(site, [sys.executable, "-c", probe], env)
    assert done.returncode == 0, done.stderr
    where, cache = done.stdout.split()
    assert where.startswith(str(site)) and cache.startswith(str(temp)), done.stdout


def test_the_command_runs_from_a_read_only_package(installed, tmp_path):
    site, _, env = installed
    scene = tmp_path / "scene.toml"
    scene.write_text((ROOT / "examples" / "pin_on_disc.toml").read_text()
                     .replace("friction = 0.5", "friction = -0.5"))
    done = read_only(site, [sys.executable, "-m", "meshwear.cli", "check", str(scene)], env)
    assert done.returncode == 2, done.stderr
    assert done.stderr.splitlines() == [
        f"meshwear: error: {scene}: contact.friction: must be >= 0, got -0.5"], done.stderr

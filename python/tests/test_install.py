"""cmake --install puts the package where /usr/bin/python3 imports it, finding the prefix's programs."""
import os
import subprocess
import sys
import sysconfig

import pytest

BUILD = os.environ.get("DDSWARM_BUILD")


@pytest.mark.skipif(not BUILD, reason="DDSWARM_BUILD (the build tree) not set")
def test_install_into_a_prefix(tmp_path):
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", BUILD, "--prefix", str(prefix)], check=True,
                   capture_output=True)
    ver = f"python{sys.version_info.major}.{sys.version_info.minor}"
    site = prefix / "lib" / ver / "dist-packages"
    assert (site / "ddswarm" / "__init__.py").exists()
    # Debian's Python searches exactly this folder for the /usr/local prefix.
    local = sysconfig.get_path("platlib", vars={"platbase": "/usr", "base": "/usr"})
    assert local == f"/usr/local/lib/{ver}/dist-packages"
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "DDSWARM_BIN")}
    env["PYTHONPATH"] = str(site)
    code = ("import ddswarm, os; print(ddswarm.__file__); print(ddswarm.bin_dir()); "
            "print(os.access(ddswarm.program('ddswarm-launch'), os.X_OK))")
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True,
                         text=True, env=env, cwd=tmp_path).stdout.split("\n")
    assert out[0].startswith(str(site))
    assert out[1] == str(prefix / "bin")
    assert out[2] == "True"

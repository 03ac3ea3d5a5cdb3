"""A minimal in-tree PEP 517 build backend: `pip install .` builds the `pic` module with CMake.

No build requirements (pyproject.toml's `requires = []`), so pip needs no package index, with
or without --no-build-isolation: CMake builds the target pic_python (scripts/setup.sh installs
what it needs), and the wheel is zipped here from build-wheel/python/pic/.

Config settings (pip install . --config-settings KEY=VALUE):
  build-dir=DIR   CMake build directory (default: build-wheel/ in the source tree). An existing
                  build directory (say build/) is reused as configured, only with the Python
                  module switched on for this interpreter.
  jobs=N          parallel build jobs (default: the CPU count)
"""
import base64
import hashlib
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
NAME = "pic"


def _version():
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(pic VERSION ([0-9.]+)", text).group(1)


def _tag():
    impl = f"cp{sys.version_info[0]}{sys.version_info[1]}"
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    return f"{impl}-{impl}-{platform}"


def _setting(config_settings, key, default):
    return (config_settings or {}).get(key, default)


def _build(config_settings):
    build = Path(_setting(config_settings, "build-dir", ROOT / "build-wheel"))
    if not build.is_absolute():
        build = ROOT / build
    fresh = not (build / "CMakeCache.txt").exists()
    configure = ["cmake", "-S", str(ROOT), "-B", str(build), "-DPIC_BUILD_PYTHON=ON"]
    if fresh:  # an existing build keeps its interpreter (the suffix is checked below)
        configure += [f"-DPython3_EXECUTABLE={sys.executable}", "-DCMAKE_BUILD_TYPE=Release",
                      "-DPIC_BUILD_TESTS=OFF", "-DPIC_BUILD_CLI=OFF"]
        if shutil.which("ninja"):
            configure += ["-G", "Ninja"]
    subprocess.run(configure, check=True, stdout=sys.stderr)
    jobs = str(_setting(config_settings, "jobs", os.cpu_count() or 1))
    subprocess.run(["cmake", "--build", str(build), "--target", "pic_python", "-j", jobs], check=True,
                   stdout=sys.stderr)
    package = build / "python" / NAME
    modules = list(package.glob("_pic*.so"))
    if not modules:
        sys.exit("pic: the Python module was not built: CMake found no pybind11 or no Python headers "
                 "(scripts/setup.sh installs pybind11-dev and python3-dev)")
    suffix = sysconfig.get_config_var("EXT_SUFFIX")
    if not any(m.name == "_pic" + suffix for m in modules):
        sys.exit(f"pic: {build} builds the module for another Python ({modules[0].name}); "
                 "use a fresh build-dir")
    return package


def _metadata(version):
    return (f"Metadata-Version: 2.1\nName: {NAME}\nVersion: {version}\n"
            "Summary: Solids as points with implicit connectivity: sample, CSG, contour, render\n"
            "Requires-Python: >=3.8\nRequires-Dist: numpy\n")


def _dist_info_files(version):
    wheel = f"Wheel-Version: 1.0\nGenerator: pic_build\nRoot-Is-Purelib: false\nTag: {_tag()}\n"
    return {"METADATA": _metadata(version), "WHEEL": wheel}


def get_requires_for_build_wheel(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    version = _version()
    dist_info = Path(metadata_directory) / f"{NAME}-{version}.dist-info"
    dist_info.mkdir(parents=True, exist_ok=True)
    for name, text in _dist_info_files(version).items():
        (dist_info / name).write_text(text)
    return dist_info.name


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    version = _version()
    package = _build(config_settings)
    wheel_name = f"{NAME}-{version}-{_tag()}.whl"
    dist_info = f"{NAME}-{version}.dist-info"
    records = []

    def add(zf, arcname, data):
        zf.writestr(arcname, data)
        digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
        records.append(f"{arcname},sha256={digest},{len(data)}")

    with zipfile.ZipFile(Path(wheel_directory) / wheel_name, "w", zipfile.ZIP_DEFLATED) as zf:
        for f in sorted(package.iterdir()):
            if f.is_file() and (f.suffix in (".py", ".pyi", ".so") or f.name == "py.typed"):
                add(zf, f"{NAME}/{f.name}", f.read_bytes())
        for name, text in _dist_info_files(version).items():
            add(zf, f"{dist_info}/{name}", text.encode())
        records.append(f"{dist_info}/RECORD,,")
        zf.writestr(f"{dist_info}/RECORD", "\n".join(records) + "\n")
    return wheel_name

"""Makes PyPI's torch wheel, installed with `pip install --no-deps`, import and run on the CPU alone.

PyPI's Linux torch wheel is a CUDA build: its libraries list the NVIDIA libraries (cuBLAS, cuDNN,
NCCL, ...: the nvidia-* and cuda-* wheels, 3 GB installed, plus 1 GB of triton) as DT_NEEDED, so the
dynamic loader refuses to load torch without them, although CPU code never calls into them. This
script writes a tiny stub library for each missing one (same soname, same symbol versions, every
symbol torch imports from it defined as a function that answers "no CUDA device") into the
directory the real ones would occupy (site-packages/nvidia/cu13/lib for torch 2.15, on torch's own
RPATH). torch.cuda.is_available() then answers False, as on any machine without an NVIDIA driver,
a CUDA tensor raises "No CUDA GPUs are available", and everything on the CPU works. The CPU wheel
index (download.pytorch.org) would make this unnecessary, but CI can only reach PyPI.

Run it with the venv's python after installing torch: `python torch_cpu_stubs.py`. It needs a C
compiler (`cc`) and `readelf` (binutils), both present wherever the Rust toolchain builds.
It writes nothing when torch already loads (for example when the real NVIDIA wheels are installed).
"""

import ctypes
import importlib.util
import os
import re
import shutil
import subprocess
import sys
import tempfile

# cudaErrorNoDevice, CUDA_ERROR_NO_DEVICE: "no CUDA-capable device", which torch handles gracefully.
NO_DEVICE = 100
MESSAGE = "CUDA is not available: this torch runs on the CPU only (stub library from torch_cpu_stubs.py)"
# The driver itself: only torch's NVRTC helper needs it, and that one is loaded on demand by CUDA code.
NEVER_STUB = {"libcuda.so.1"}


def readelf(*args):
    return subprocess.run(["readelf", "-W", *args], check=True, capture_output=True, text=True).stdout


def elf_files(root):
    for dirpath, _, names in os.walk(root):
        for name in names:
            path = os.path.join(dirpath, name)
            if re.search(r"\.so(\.\d+)*$", name) and os.path.isfile(path) and not os.path.islink(path):
                with open(path, "rb") as f:
                    if f.read(4) == b"\x7fELF":
                        yield path


def loads(soname):
    try:
        ctypes.CDLL(soname)
        return True
    except OSError:
        return False


def main():
    spec = importlib.util.find_spec("torch")
    if spec is None or not spec.submodule_search_locations:
        sys.exit("torch is not installed in this interpreter")
    torch_dir = spec.submodule_search_locations[0]
    probe = subprocess.run([sys.executable, "-c", "import torch"], capture_output=True, text=True)
    if probe.returncode == 0:
        print("torch_cpu_stubs: torch already imports, nothing to do")
        return

    for tool in ("readelf", "cc"):
        if shutil.which(tool) is None:
            sys.exit(f"torch_cpu_stubs: needs `{tool}` (apt-get install binutils gcc)")
    files = list(elf_files(torch_dir))
    # Where the real libraries would be: an nvidia/ directory on the RPATH of torch's libraries.
    lib_dir = os.path.join(torch_dir, "lib")
    dynamic = readelf("-d", os.path.join(lib_dir, "libtorch_global_deps.so"))
    rpath = re.search(r"\((?:RPATH|RUNPATH)\)\s+Library r(?:un)?path: \[([^\]]*)\]", dynamic)
    dirs = [d.replace("$ORIGIN", lib_dir) for d in (rpath.group(1).split(":") if rpath else [])]
    dirs = [os.path.normpath(d) for d in dirs if "/nvidia/" in d]
    if not dirs:
        sys.exit("torch_cpu_stubs: torch's libraries have no nvidia/ directory on their RPATH")
    out_dir = dirs[-1]
    own = {os.path.basename(f) for f in files}
    needed = {}  # soname -> set of version names torch requires from it
    undefined = set()  # (symbol, version or None)
    defined = set()
    for f in files:
        for soname in re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", readelf("-d", f)):
            needed.setdefault(soname, set())
        current = None
        for line in readelf("-V", f).splitlines():
            m = re.search(r"File: (\S+)", line)
            if m:
                current = m.group(1)
                needed.setdefault(current, set())
                continue
            m = re.search(r"Name: (\S+)\s+Flags", line)
            if m and current:
                needed[current].add(m.group(1))
        section = readelf("--dyn-syms", f)
        for line in section.splitlines():
            cols = line.split()
            if len(cols) < 8 or not cols[0].endswith(":"):
                continue
            bind, ndx, name = cols[4], cols[6], cols[7]
            sym, _, version = name.partition("@")
            version = version.lstrip("@") or None
            if ndx == "UND":
                if bind != "WEAK":
                    undefined.add((sym, version))
            else:
                defined.add(sym)

    missing = sorted(s for s in needed if s not in own and s not in NEVER_STUB and not loads(s))
    if not missing:
        sys.exit("torch does not import, but no library is missing:\n" + probe.stderr)
    # The interpreter itself (the Python C API) and the system libraries torch links.
    system = [ctypes.CDLL(None)]
    system += [ctypes.CDLL(s) for s in needed if s not in own and s not in missing and s not in NEVER_STUB]
    stub_versions = {v for s in missing for v in needed[s]}

    def in_system(sym):
        return any(hasattr(lib, sym) for lib in system)

    by_version = {}
    orphans = set()  # unversioned, defined nowhere: they come from one of the unversioned missing libs
    for sym, version in undefined:
        if version in stub_versions:
            by_version.setdefault(version, set()).add(sym)
        elif version is None and sym not in defined and not in_system(sym):
            orphans.add(sym)
    symbols = sorted(set().union(orphans, *by_version.values()))

    src = ["/* generated by torch_cpu_stubs.py */", f'static const char msg[] = "{MESSAGE}";']
    for i, sym in enumerate(symbols):
        if re.search(r"Error(String|Name)$|GetString$", sym):
            src.append(f'const char *s{i}(void) __asm__("{sym}"); const char *s{i}(void) {{ return msg; }}')
        else:
            src.append(f'long s{i}(void) __asm__("{sym}"); long s{i}(void) {{ return {NO_DEVICE}; }}')
    os.makedirs(out_dir, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        c_file = os.path.join(tmp, "stub.c")
        with open(c_file, "w") as f:
            f.write("\n".join(src) + "\n")
        obj = os.path.join(tmp, "stub.o")
        subprocess.run(["cc", "-c", "-fPIC", "-O0", "-w", "-o", obj, c_file], check=True)
        for soname in missing:
            cmd = ["cc", "-shared", "-o", os.path.join(out_dir, soname), obj, f"-Wl,-soname,{soname}"]
            if needed[soname]:
                script = os.path.join(tmp, soname + ".map")
                with open(script, "w") as f:
                    for version in sorted(needed[soname]):
                        syms = "".join(f' "{s}";' for s in sorted(by_version.get(version, ())))
                        f.write(f"{version} {{ global:{syms} }};\n")
                cmd.append(f"-Wl,--version-script={script}")
            subprocess.run(cmd, check=True)
    print(f"torch_cpu_stubs: {len(missing)} stub libraries ({len(symbols)} symbols) in {out_dir}:")
    print("  " + " ".join(missing))
    check = subprocess.run(
        [sys.executable, "-c", "import torch; assert not torch.cuda.is_available(); print(torch.ones(2) @ torch.ones(2))"],
        capture_output=True, text=True)
    if check.returncode != 0:
        sys.exit("torch still does not import:\n" + check.stderr)


if __name__ == "__main__":
    main()

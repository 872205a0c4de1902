"""Print an OpenBLAS core type this CPU runs other than the one OpenBLAS picks by itself.

Sandybridge (AVX) runs on every x86-64 CPU with AVX; where that is already the native
choice, Nehalem (SSE4.2) is taken instead.
"""

import threadpoolctl

native = {i.get("architecture") for i in threadpoolctl.threadpool_info()
          if i.get("internal_api") == "openblas"}
print("Nehalem" if "Sandybridge" in native else "Sandybridge")

import os
import sys

# one BLAS thread in every test process and the commands it starts, before numpy loads OpenBLAS: the
# filters' matrices are small and its threads cost more than they give, more so beside a second
# worker on two cores (driver.blas)
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import matplotlib  # noqa: E402

matplotlib.use("Agg")
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

"""Every file of four runs holds the values it held before the results became typed values (tests/golden.py):
the README's demo, a study, a run behind a spring and a fit, timings and versions aside."""
import json
import os

import pytest

from conftest import run_cli
from golden import CASES, GOLDEN, run_case, same


@pytest.mark.parametrize("name", list(CASES))
def test_files_hold_the_values_they_held(name, tmp_path):
    if name == "fit":
        pytest.importorskip("scipy.optimize")
    new = run_case(name, str(tmp_path), run_cli)
    with open(os.path.join(GOLDEN, f"{name}.json")) as f:
        old = json.load(f)
    # through JSON as the golden digests were, so that tuples and lists compare alike
    diffs = same(json.loads(json.dumps(new)), old)
    assert not diffs, f"{len(diffs)} differences, the first: " + "; ".join(diffs[:8])

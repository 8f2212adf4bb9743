"""A synthesised network flows into the time simulation and the nonlinear truth study."""

import math

import pytest

from inerterlab.network_truth import network_truth
from inerterlab.synthesis.design import synthesize_design


@pytest.mark.slow
def test_synthesised_network_in_truth_and_simulation():
    from inerterlab import excitation as ex
    from inerterlab.systems import quarter_car

    out = synthesize_design(1, "body_acc", static_stiffness=90_000.0, starts=1, compare=False)
    net = out["network"]
    design = ",".join(f"{k}={v!r}" for k, v in net["parameters"].items())
    res = network_truth(
        layouts=(),
        custom=(net["text"], design),
        variant_list=["ideal"],
        inputs=["bump"],
        horizon=2.0,
    )
    assert res.layout_text("custom") == net["text"]
    gain = float(res.gains["rms_body_acc_wk"].sel(layout="custom", variant="ideal", input="bump"))
    assert math.isfinite(gain)
    # the study's point is the model core's simulation of that network
    sim = quarter_car(net["text"], net["parameters"]).simulate(ex.bump(0.05), horizon=2.0)
    base = float(res.dataset["baseline"].sel(metric="rms_body_acc_wk", input="bump"))
    assert gain == pytest.approx(100 * (1 - sim.metrics["rms_body_acc_wk"] / base), rel=1e-9)

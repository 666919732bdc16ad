"""Records reference flights with the code before the layered move (commit cc607e3)."""
import warnings, numpy as np, quadcruise as qc
from quadcruise.disturbances import Environment, Turbulence, RotorLoss, SensorNoise, ConstantWind, Gust, with_drag
from quadcruise.montecarlo import Population, montecarlo
warnings.simplefilter("ignore")
out = {}
def keep(name, res):
    out[name + "/states"] = res.states
    out[name + "/commands"] = res.commands
    out[name + "/t"] = res.t
    m = res.metrics()
    for c in m.columns:
        try:
            out[name + "/metric/" + c] = m[c].to_numpy(dtype=float)
        except Exception:
            pass
keep("circle_nlpd", qc.fly("circle", "nlpd", log_every=10))
keep("square_gonzalez", qc.fly("square", "gonzalez", duration=12.0, log_every=10))
keep("step_se3", qc.fly("step", "se3", log_every=10))
keep("step_cascade", qc.fly("step", "cascade", log_every=10))
keep("step_full", qc.fly("step", "nlpd", full_dynamics=True, log_every=10))
env = Environment(wind=ConstantWind(velocity=(1.0, 0.5, 0.0)), turbulence=Turbulence(intensity="moderate"),
                  rotor_loss=RotorLoss(rotor=1, fraction=0.2, time=4.0))
keep("circle_env", qc.fly("circle", "nlpd", duration=8.0, vehicle=with_drag(qc.Vehicle.paper().replace(m=3.8)),
     controller_vehicle=qc.Vehicle.paper(), seed=7, log_every=10, **env.kwargs(),
     **SensorNoise(position_std=0.01, angle_std=0.002, delay=0.004).kwargs(dt=1e-3)))
keep("batch_mass", qc.fly("circle", "nlpd", vehicle=qc.Vehicle(m=np.linspace(2.5, 4.5, 6)), duration=5.0, log_every=50))
keep("gust_dt2", qc.fly("step", "nlpd", dt=2e-3, vehicle=with_drag(qc.Vehicle.paper()), duration=6.0, log_every=5,
     **Environment(gust=Gust(amplitude=(2.0, 0.0, 0.0), start=1.0, duration=1.0)).kwargs()))
st = qc.replay(qc.read_duty_csv("examples/pwm_step.csv"))
out["replay/states"] = np.asarray(st.states if hasattr(st, "states") else st)
mc = montecarlo("circle", "nlpd", Population(mass_spread=0.1, environment=Environment(turbulence=Turbulence(intensity="light"))),
                n=16, seed=3, duration=4.0, scheduler="none")
tab = mc.to_pandas() if hasattr(mc, "to_pandas") else mc.table
for c in tab.columns:
    try:
        out["mc/" + c] = tab[c].to_numpy(dtype=float)
    except Exception:
        pass
np.savez_compressed("tests/support/reference_flights.npz", **out)
print(len(out), "arrays")

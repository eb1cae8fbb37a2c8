#!/usr/bin/env python3
"""The FMI 2.0 FMUs and the SSP through importers nobody here wrote (../shared/peers builds them):
FMPy validate and simulate, fmusim, and FMPy's simulate_ssp on build/release/ssp/TissueHaptic.ssp
with the hand pressing the frog's back; plots the forces (docs/fmi2_ssp_press.png).

Not a test (the project's tests must not need the peers): run by hand, figures in docs/FMI2.md.
  PYTHONPATH=/work/peers/fmi/src/FMPy/src /usr/bin/python3 tests/bench/fmi2_peers.py \
      [--build build/release] [--fmusim /work/peers/fmi/install/bin/fmusim] [--plot docs/fmi2_ssp_press.png]
"""
import argparse, os, subprocess, sys, tempfile, time

def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--build", default="build/release")
    p.add_argument("--fmusim", default="/work/peers/fmi/install/bin/fmusim")
    p.add_argument("--plot", default="docs/fmi2_ssp_press.png")
    p.add_argument("--stop-time", type=float, default=0.8)
    a = p.parse_args()
    from fmpy import simulate_fmu
    from fmpy.validation import validate_fmu
    from fmpy.ssp.ssd import read_ssd
    from fmpy.ssp.simulation import simulate_ssp

    fmus = {n: os.path.join(a.build, "fmus", "fmi2", n + ".fmu") for n in ("Tissue", "HapticLoop")}
    for name, fmu in fmus.items():
        problems = validate_fmu(fmu)
        print(f"FMPy validate {name}: {'no problems' if not problems else problems}")
        result = simulate_fmu(fmu, stop_time=0.1)
        print(f"FMPy simulate {name} (0.1 s): {len(result)} rows, {len(result.dtype.names) - 1} outputs")
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "out.csv")
            rc = subprocess.run([a.fmusim, "--interface-type", "cs", "--stop-time", "0.1", "--output-file", out, fmu],
                                capture_output=True, text=True).returncode
            rows = sum(1 for _ in open(out)) - 1 if os.path.exists(out) else 0
            print(f"fmusim {name} (0.1 s, defaults): exit {rc}, {rows} rows")

    state_round_trip(fmus["Tissue"])

    ssp = os.path.join(a.build, "ssp", "TissueHaptic.ssp")
    ssd = read_ssd(ssp)  # validates SystemStructure.ssd and the .ssv against FMPy's SSP 1.0 schemas
    parameters = ssd.system.parameterBindings[0].parameterValues[0]
    print(f"SSP {ssd.system.name}: components {[c.name for c in ssd.system.elements]}, "
          f"{len(ssd.system.connections)} connections, parameters {[(q.name, q.value) for q in parameters.parameters]}")
    # The hand: 1 cm above the frog's back (z = 36 mm) down to 3 mm into it in 0.5 s, then held.
    press_s = 0.5
    inputs = {"device.toolMode": lambda t: 1, "device.position[1]": lambda t: -0.007, "device.position[2]": lambda t: 0.0,
              "device.position[3]": lambda t: 0.046 - 0.013 * min(1.0, t / press_s)}
    started = time.perf_counter()
    r = simulate_ssp(ssp, stop_time=a.stop_time, step_size=0.001, parameter_set=parameters, input=inputs)
    wall = time.perf_counter() - started
    t = r["time"]
    if os.environ.get("SHOW_COLUMNS"): print([n for n in r.dtype.names if "force" in n.lower()])
    fz_tissue = r["Tissue.contact.force[3]"]
    fz_device = r["device.force[3]"]
    held = [k for k in range(len(t)) if t[k] >= press_s + 0.2]
    print(f"FMPy simulate_ssp ({a.stop_time} s at 1 ms, {wall:.1f} s wall): {len(t)} rows; "
          f"held press (t >= {press_s + 0.2} s): tissue contact.force[3] {fz_tissue[held].mean():.4f} N, "
          f"device.force[3] {fz_device[held].mean():.4f} N")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 3.6), dpi=110)
    ax.plot(t, fz_device, label="device.force[3]: the system output, to the hand")
    ax.plot(t, fz_tissue, "--", label="Tissue contact.force[3] (on the tool)")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("force z [N]")
    ax.set_title("TissueHaptic.ssp in FMPy's simulate_ssp: the frog pressed 3 mm (FMI 2.0)")
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left")
    fig.tight_layout()
    fig.savefig(a.plot)
    print("plot:", a.plot)

def state_round_trip(fmu):
    """The 2.0 Tissue's FMU state through FMPy's FMU2Slave: pressed 30 steps, a state taken and
    serialized, ten more steps; the state set back and the same ten; then the bytes deserialized,
    set, and the same ten again. The contact force must repeat bit for bit."""
    import shutil
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    md = read_model_description(fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    folder = extract(fmu)
    s = FMU2Slave(guid=md.guid, unzipDirectory=folder, modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName="state")
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    s.setInteger([vr["tool.mode"]], [1])
    position = [vr["tool.position[1]"], vr["tool.position[2]"], vr["tool.position[3]"]]

    def run(first, count):
        forces = []
        for k in range(first, first + count):
            s.setReal(position, [-0.007, 0.0, 0.046 - 0.013 * min(1.0, k / 30)])
            s.doStep(currentCommunicationPoint=k * 0.01, communicationStepSize=0.01)
            forces.append(s.getReal([vr["contact.force[3]"]])[0])
        return forces

    run(0, 30)
    state = s.getFMUstate()
    data = s.serializeFMUstate(state)
    first = run(30, 10)
    s.setFMUstate(state)
    again = run(30, 10)
    restored = s.deSerializeFMUstate(data)
    s.setFMUstate(restored)
    from_bytes = run(30, 10)
    print(f"FMPy FMU2Slave state (Tissue): {len(data)} bytes serialized; the ten steps after set "
          f"{'repeat bitwise' if again == first else 'DIFFER'}, after deserialize "
          f"{'repeat bitwise' if from_bytes == first else 'DIFFER'} (force {first[-1]:.4f} N)")
    s.freeFMUstate(state)
    s.freeFMUstate(restored)
    s.terminate()
    s.freeInstance()
    shutil.rmtree(folder)


if __name__ == "__main__":
    main()

"""Free blocks dropped onto the shipped gate's surge (docs/CORRECTIONS.md "The walls inside the structure's
sub-steps"): the gate's solid made a block held nowhere, 1,100-8,000 kg/m3, E 12 MPa or 1 GPa, 3-12 cm wide, 1-12 cm
above the floor, WCSPH or ISPH at 4-8 mm, 0.2 s in-process. Prints per scene the status and energy_growth.largest
(in budgets) of each variant OFF:ZETA, where ZETA is solid[0].mesh_damping and OFF is put in COSIM_WALL_OFFSET (read
only by the build of docs/experiments/wall_offset.diff; give 0 otherwise).

    cargo build --release && python3 docs/experiments/slam_sweep.py SEED COUNT 0:0 0:0.02
"""
import random, subprocess, sys, os, json, tempfile, concurrent.futures as cf
seed=int(sys.argv[1]); n=int(sys.argv[2]); variants=sys.argv[3:]  # each "OFF:ZETA"
ROOT=os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
C=os.path.join(ROOT,"target/release/cosim"); TMP=tempfile.mkdtemp(prefix="slam")
def sets_for(k):
    r=random.Random(seed*1000+k)
    sp=r.choice([0.004,0.006,0.008])
    x0=r.uniform(0.1,0.3); y0=r.uniform(0.01,0.12); w=r.uniform(0.03,0.12); h=r.uniform(0.01,0.05)
    s=[f"fluid.spacing={sp}","run.end_time=0.2",f"solid[0].min=[{x0:.5f},{y0:.5f}]",f"solid[0].max=[{x0+w:.5f},{y0+h:.5f}]",
       f"solid[0].divisions=[{max(2,int(w/0.003))},{max(1,int(h/0.003))}]",f"probe[0].point=[{x0+w/2:.5f},{y0:.5f}]",f"probe[1].point=[{x0+w/2:.5f},{y0:.5f}]",
       "solid[0].fixed=[]",'solid[0].element="%s"'%r.choice(["tri3","quad4"]),
       f"solid[0].material.density={r.choice([1100.0,2700.0,8000.0])}", f"solid[0].material.youngs_modulus={r.choice([12e6,1e9])}",
       "coupling.fluid_substeps=%d"%r.choice([1,8]), 'fluid.solver="%s"'%r.choice(["wcsph","wcsph","isph"])]
    return s
def run(job):
    k,v=job; off,z=v.split(":"); out=f"{TMP}/o{k}_{off}_{z}"
    args=[C,"run",os.path.join(ROOT,"scenes/elastic_gate.toml"),"--in-process","--quiet","--out",out]
    for s in sets_for(k)+[f"solid[0].mesh_damping={z}"]: args+=["--set",s]
    env=dict(os.environ,COSIM_WALL_OFFSET=off)
    try:
        p=subprocess.run(args,capture_output=True,text=True,timeout=300,env=env); rc=p.returncode
        try: s=json.load(open(out+"/summary.json")); g=s.get("energy_growth",{}).get("largest"); st=s["status"]
        except Exception: g=None; st="none"
    except subprocess.TimeoutExpired: rc=124; g=None; st="timeout"
    subprocess.run(["rm","-rf",out]); return k,v,rc,st,g
jobs=[(k,v) for k in range(n) for v in variants]
res={}
with cf.ThreadPoolExecutor(2) as ex:
    for k,v,rc,st,g in ex.map(run,jobs):
        res.setdefault(k,{})[v]=(st,g)
        if len(res[k])==len(variants):
            print(k, " | ".join(f"{vv}: {res[k][vv][0][:4]} {res[k][vv][1] if res[k][vv][1] is None else round(res[k][vv][1],3)}" for vv in variants), "  ", " ".join(x for x in sets_for(k) if "density=" in x or "solver" in x or "spacing" in x), flush=True)

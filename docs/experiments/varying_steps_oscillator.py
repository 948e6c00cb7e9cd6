"""The central difference (kick-drift-kick) of one oscillator x'' = -w^2 x, advanced in calls of 4 equal sub-steps
whose length changes from call to call, as the structure's sub-steps follow a coupling step that follows the fluid's
(docs/CORRECTIONS.md "The structure's sub-steps of changing length"). Each sub-step is stable on its own (w h < 2);
the energy still grows, because every step length conserves a different quadratic form and their product is not
bounded. Prints the largest energy over its start in 20,000 calls, for w h (the longest step) and the relative spread
of the steps (each call's h drawn from [w h (1 - spread), w h]).

    python3 docs/experiments/varying_steps_oscillator.py
"""
import random


def largest_gain(wh, spread, calls=20000, seed=1):
    r = random.Random(seed)
    x, v, worst = 1.0, 0.0, 1.0
    for _ in range(calls):
        h = wh * (1.0 - spread * r.random())
        for _ in range(4):
            v -= 0.5 * h * x
            x += h * v
            v -= 0.5 * h * x
        worst = max(worst, (v * v + x * x) / 1.0)
    return worst


for wh in (1.8, 1.4, 1.0, 0.6):
    print(f"w h = {wh}: " + ", ".join(f"spread {s:.2f}: {largest_gain(wh, s):.3g}" for s in (0.0, 0.02, 0.1, 0.3)))

#!/usr/bin/env python3
"""Print the trimmed JSON examples of docs/diagnose-json.md from a `diagnose --format json` output
(or a `diagnose --self-test --format json` one).

Numbers are rounded to 4 significant digits; `…` marks left-out entries; `inputs`,
`effective_noise` and `turns` are left out. Usage (the commands of the doc's example, then):

    gyro-cli diagnose --train r1.csv r2.csv r3.csv --holdout r4.csv r5.csv r6.csv \\
        --format json -o corrected.json > out.json
    python3 scripts/diagnose_json_example.py out.json

or `gyro-cli diagnose --self-test --seed 8 --only scale_factor --format json > st.json`, then
`python3 scripts/diagnose_json_example.py st.json`.
"""
import json
import sys


def r4(x):
    if isinstance(x, float):
        return float(f"{x:.4g}")
    if isinstance(x, list):
        return [r4(v) for v in x]
    if isinstance(x, dict):
        return {k: r4(v) for k, v in x.items()}
    return x


def j(x):
    return json.dumps(r4(x), ensure_ascii=False)


def self_test(d):
    out = ["{", f' "seed": {d["seed"]},', f' "magnitudes": {j(d["magnitudes"][:2])[:-1]}, …],']
    case = dict(d["cases"][0])
    effects = case.pop("effects")
    first = j(case)[:-1] + f', "effects": [{j(effects[0])}, …]}}'
    out.append(f' "cases": [\n   {first}, …],')
    for k in d:
        if k not in ("seed", "magnitudes", "cases"):
            out.append(f' "{k}": {j(d[k])},')
    out[-1] = out[-1].rstrip(",")
    out.append("}")
    print("\n".join(out))


def main():
    with open(sys.argv[1]) as f:
        d = json.load(f)
    if "cases" in d:
        self_test(d)
        return
    out = ["{", f' "gap": {j(d["gap"])},', ' "where": [']
    where = [j(w) for w in d["where"][:3]]
    out.append("   " + ",\n   ".join(where) + ", …],")
    out.append(' "effects": [')
    effects = [j(e) for e in d["effects"][:3]]
    out.append("   " + ",\n   ".join(effects) + ", …],")
    out.append(f' "verdict": {j(d["verdict"])},')
    out.append(f' "unexplained": {j(d["unexplained"])},')
    out.append(f' "untestable": {j(d["untestable"])},')
    m = d["model"]
    out.append(' "model": {')
    out.append(f'   "sensor": {j(m["sensor"])},')
    out.append('   "notes": [')
    out.append("     " + ",\n     ".join(json.dumps(n, ensure_ascii=False) for n in m["notes"]) + "],")
    out.append(f'   "rest_noise": {j(m["rest_noise"])},')
    out.append(f'   "effects": {j(m["effects"])}}},')
    runs = d["runs"]
    first = [next(r for r in runs if r["role"] == role) for role in ("train", "holdout")]
    out.append(' "runs": [')
    out.append("   " + ",\n   ".join(j(r) for r in first) + ", …],")
    c = d["compensation"]
    out.append(
        f' "compensation": {{"corrected": {j(c["corrected"])}, "not_corrected": '
        f'{j(c["not_corrected"])}, "runs": ['
    )
    out.append(f'   {j(c["runs"][0])}, …]}}')
    out.append("}")
    print("\n".join(out))


if __name__ == "__main__":
    main()

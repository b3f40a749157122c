"""Paper 002 report section: the verdict rules on small synthetic tables."""



def test_paper002_rules():
    from scfmu.papers.paper002 import report as p
    fo = {"settling_s": 5.0, "overshoot_pct": 1.0, "mae_deg": 3.0}
    it = {"settling_s": 6.0, "overshoot_pct": 1.0, "mae_deg": 3.1}
    r = p.pair_rule(fo, it)
    assert r["better"] == 2 and r["worse"] == 0 and r["holds"]
    assert not p.pair_rule({**fo, "overshoot_pct": 2.0}, it)["holds"]          # worse on one metric
    assert not p.pair_rule(it, it)["holds"]                                       # all ties
    mae = {"PD": 3.0, "PID": 3.2, "FOPD": 2.9, "FOPID": 3.1}
    assert p.phase_rule(mae)["holds"]
    assert not p.phase_rule({**mae, "PID": 2.95, "FOPID": 2.9})["holds"]          # PID better than PD
    sw = {"PD": [1, 2, 3], "PID": [1, 3, 5], "FOPD": [1, 1.4, 1.8], "FOPID": [1, 1.5, 2]}
    assert p.spread_rule(sw)["holds"] and not p.spread_rule(sw, 0.3)["holds"]
    b = p.sweep_better_rule({"PD": [2, 2, 2, 2], "PID": [2, 2, 2, 2], "FOPD": [1, 1, 1, 3], "FOPID": [1, 1, 1, 1]})
    assert b["FOPD>PD"] == (3, 4) and b["holds"]
    assert not p.sweep_better_rule({"PD": [2, 2], "PID": [2, 2], "FOPD": [1, 3], "FOPID": [1, 1]})["holds"]
    assert p.grows_rule({"PD": [1, 1, 2], "FOPD": [0.5, 0.6, 0.7]}) and not p.grows_rule({"PD": [2, 1]})
    wt = {"PD": [3, 2, 4], "PID": [3, 2, 4], "FOPD": [2.5, 1.9, 3], "FOPID": [2.5, 1.9, 3]}
    ds = {"PD": [2, 3, 5], "PID": [2, 3, 5], "FOPD": [1.5, 2, 3], "FOPID": [1.5, 2, 3]}
    assert all(p.c4_parts(wt, ds).values())
    parts = p.c4_parts(wt, {**ds, "FOPD": [1.5, 1.4, 6]})      # fractional varies more and the error falls once
    assert not parts["vary less, disturbance"] and not parts["error grows with disturbance"] and parts["better, wheel T"]

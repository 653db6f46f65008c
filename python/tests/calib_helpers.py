"""What the calibration and thermal tests share: a short chamber protocol and the
round-trip check of the objects backed by a model file (CalibrationResult,
ThermalModel)."""

import pickle


def chamber_trajectory(temperatures_c, soak_s):
    """The `[trajectory]` table of a short chamber protocol at 20 Hz-friendly lengths:
    10-s position dwells, one revolution per rate segment at 60 deg/s, a 1-s thermal
    lag (settled within every soak)."""
    return f"""[trajectory]
type = "chamber"
temperatures_c = {list(map(float, temperatures_c))!r}
soak_s = {float(soak_s)!r}
position_dwell_s = 10.0
move_s = 2.0
rate_deg_s = 60.0
rate_revolutions = 1
spin_s = 1.0
lag_tau_s = 1.0
"""


def assert_round_trips(obj, path):
    """``from_dict(to_dict())``, ``save``/``load`` and pickle give the same file, text
    for text; returns (loaded from the file, unpickled)."""
    cls = type(obj)
    d = obj.to_dict()
    back = cls.from_dict(d)
    assert back.to_dict() == d and back.to_toml() == obj.to_toml()
    obj.save(path)
    assert path.read_text() == obj.to_toml()
    loaded = cls.load(path)
    assert loaded.to_dict() == d and loaded.to_toml() == obj.to_toml()
    again = pickle.loads(pickle.dumps(obj))
    assert again.to_dict() == d
    return loaded, again

"""``fccqp.tuning`` gives Python every constant of ``tuning.pxd``, at its C value."""

import re
from pathlib import Path

import fccqp.tuning as tuning

PXD = Path(tuning.__file__).with_name("tuning.pxd")


def test_every_constant_of_tuning_pxd_is_exposed_at_its_c_value():
    text = PXD.read_text()
    defines = dict(re.findall(r"#define FCCQP_(\w+) (\S+)", text))
    declared = re.findall(r'^    const (\w+) (\w+) "FCCQP_\2"$', text, re.M)
    assert sorted(name for _, name in declared) == sorted(defines)
    for ctype, name in declared:
        value = getattr(tuning, name)
        assert value == float(defines[name]), name
        assert type(value) is (float if ctype == "double" else int), name

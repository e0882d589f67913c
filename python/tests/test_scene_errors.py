"""A bad scene raises SceneError carrying the message and the JSON path as the program prints
them."""
import json
import subprocess

import pytest

import pfsph


def test_bad_key_names_the_key(column):
    column["solver"]["bogus_key"] = 1
    with pytest.raises(pfsph.SceneError) as ei:
        pfsph.Simulation(column)
    e = ei.value
    assert e.path == "$.solver.bogus_key"
    assert e.key == "bogus_key"
    assert e.source == "<scene>"
    assert "bogus_key" in str(e) and "valid keys" in e.reason
    assert isinstance(e, ValueError) and e.code == -2


def test_bad_value_in_a_list(column):
    column["phases"][0]["viscosity"] = "thick"
    with pytest.raises(pfsph.SceneError) as ei:
        pfsph.Simulation(column, source="/tmp/my_scene.json")
    assert ei.value.path == "$.phases[0].viscosity"
    assert ei.value.key == "viscosity"
    assert ei.value.source == "/tmp/my_scene.json"


def test_message_equals_the_programs(column, pfsph_bin, tmp_path):
    column["fluid"][0]["shape"] = "blob"
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(column))
    with pytest.raises(pfsph.SceneError) as ei:
        pfsph.Simulation(str(path))
    p = subprocess.run([pfsph_bin, "run", str(path), "-o", str(tmp_path / "run"), "--quiet"], capture_output=True,
                       text=True)
    assert p.returncode == 2
    assert p.stderr.strip() == "pfsph: " + ei.value.message
    assert ei.value.path.startswith("$.fluid[0]")


def test_invalid_json_file(tmp_path):
    path = tmp_path / "broken.json"
    path.write_text("{\n")
    with pytest.raises(pfsph.SceneError) as ei:
        pfsph.Simulation(path)
    assert ei.value.path == "$" and "invalid JSON" in ei.value.reason


def test_missing_file(tmp_path):
    with pytest.raises(pfsph.Error):
        pfsph.Simulation(str(tmp_path / "none.json"))

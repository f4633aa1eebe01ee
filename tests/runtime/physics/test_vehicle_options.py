"""The simulated vehicle's options are defined once (physics.vehicle.VehicleOptions): the simulator's SimConfig and
the closed loop's LoopOptions extend them without redefining one, and the command line's options are their fields'
flags (common.cli_fields), whose defaults are the fields' defaults."""

from __future__ import annotations

import argparse
import inspect
from dataclasses import fields

import pytest

from sam_runtime.common.cli_fields import add_flags, forwarded_argv, options_from
from sam_runtime.physics.vehicle import SeaFloor, SimulatedVehicle, VehicleOptions
from sam_runtime.sim.closed_loop import LoopOptions
from sam_runtime.sim.config import SimConfig

VEHICLE_FIELDS = {f.name for f in fields(VehicleOptions)}


@pytest.mark.parametrize("cls", [SimConfig, LoopOptions])
def test_the_extensions_redefine_no_vehicle_option(cls: type) -> None:
    assert issubclass(cls, VehicleOptions)
    assert not VEHICLE_FIELDS & set(inspect.get_annotations(cls))


def _parser(*, main_job: bool = False) -> argparse.ArgumentParser:
    p = argparse.ArgumentParser()
    add_flags(p, SimConfig, main_job=main_job)
    return p


def test_the_flags_defaults_are_the_fields_defaults() -> None:
    defaults = SimConfig()
    parsed = options_from(SimConfig, _parser().parse_args([]))
    assert parsed == {name: getattr(defaults, name) for name in parsed}
    assert set(parsed) == VEHICLE_FIELDS - {"params", "noise"} | {"time_scale", "truth_file", "truth_rate_hz",
                                                                  "stale_firmware"}


def test_the_main_job_forwards_what_its_sim_reads_back() -> None:
    argv = ["--seed", "7", "--sea-floor", "0:25,60:6", "--sea-floor-axis", "0.5", "--start", "1,2,3,0.25",
            "--battery-start", "50", "--battery-health", "25", "--gps-origin", "58.1,11.2", "--truth-rate", "2.5",
            "--stale-firmware", "imu, gps"]
    run = _parser(main_job=True).parse_args(argv)
    assert not hasattr(run, "time_scale")  # the main job's nodes run on the wall clock
    sim = options_from(SimConfig, _parser().parse_args(forwarded_argv(SimConfig, run)))
    assert sim == {**options_from(SimConfig, run), "time_scale": 1.0, "truth_file": None}
    config = SimConfig("can", **sim)
    assert (config.kind, config.sea_floor, config.start, config.battery_health_pct) == (
        "can", SeaFloor(25.0, ((0.0, 25.0), (60.0, 6.0)), 0.5), (1.0, 2.0, 3.0, 0.25), 25)
    assert config.stale_firmware == ("imu", "gps")


def test_a_bad_option_is_one_line() -> None:
    with pytest.raises(ValueError, match=r"^--start: expected 4 comma-separated numbers, got '1,2'$"):
        options_from(SimConfig, _parser().parse_args(["--start", "1,2"]))


def test_a_vehicle_from_options_or_keywords_is_the_same() -> None:
    a = SimulatedVehicle(LoopOptions(seed=3, start=(0.0, 0.0, 2.0, 0.0)), battery_percent=40.0)
    b = SimulatedVehicle(seed=3, start=(0.0, 0.0, 2.0, 0.0), battery_percent=40.0)
    assert a.vehicle.state == b.vehicle.state and a.options.battery_percent == b.options.battery_percent == 40.0
    assert SimConfig(seed=3).make_vehicle().options.seed == 3

"""The ROS node's settings: the CLI's validators and messages, read from YAML (no ROS needed)."""

from pathlib import Path

import pytest

from comanip.cli.main import main
from comanip.ros.node_settings import NodeSettings


@pytest.mark.parametrize("values, message", [
    ({"preset": "nonexistent"}, "preset: preset must be one of"),
    ({"preset": "franka"}, "needs a point-mass model"),
    ({"command_rate": -1.0}, "command_rate must be a finite number > 0 (Hz)"),
    ({"max_wall_time": 0}, "max_wall_time must be a finite number > 0 (s)"),
    ({"width": 0.0}, "width must be a finite number > 0 (m)"),
    ({"prior_goal": [0.1, 0.2]}, "prior_goal must have shape (3,)"),
    ({"ramp_time": -0.1}, "ramp_time must be a finite number ≥ 0 (s)"),
    ({"hand_pose_topic": ""}, "hand_pose_topic must be a non-empty string"),
    ({"equilibrium_orientation": [1, 1, 0, 0]}, "equilibrium_orientation must be a unit quaternion"),
    ({"estimation_rat": 3}, "unknown parameter(s) ['estimation_rat']"),
    ({"estimator": "mouse"}, "estimator: an online estimator must be one of"),
    ({"velocity_source": "imu"}, "velocity_source must be one of ('auto', 'twist', 'poses'), got 'imu'"),
    ({"velocity_window": -0.02}, "velocity_window must be a finite number > 0 (s)"),
])
def test_a_bad_setting_is_a_value_error_naming_it(values, message):
    with pytest.raises(ValueError) as error:
        NodeSettings.from_mapping(values)
    assert message in str(error.value)


def test_yaml_in_the_ros2_parameter_layout_or_flat_gives_the_same_settings(tmp_path):
    nested, flat = tmp_path / "nested.yaml", tmp_path / "flat.yaml"
    nested.write_text("comanip_goal:\n  ros__parameters:\n    preset: planar\n    prior_goal: [0.3, 0.1]\n    frame_id: fr3_link0\n")
    flat.write_text("preset: planar\nprior_goal: [0.3, 0.1]\nframe_id: fr3_link0\n")
    settings = NodeSettings.from_yaml(nested)
    assert settings == NodeSettings.from_yaml(flat)
    assert settings.prior_goal == (0.3, 0.1) and settings.model().d == 2
    assert NodeSettings.from_mapping(settings.to_mapping()) == settings


def test_the_command_reports_a_bad_parameter_file_in_one_line(tmp_path, capsys):
    params = tmp_path / "params.yaml"
    params.write_text("status_rate: 0\n")
    assert main(["ros", "--params", str(params)]) == 2
    assert capsys.readouterr().err.strip() == "comanip ros: error: status_rate must be a finite number > 0 (Hz), got 0"


def test_the_preset_and_rate_on_the_command_line_override_the_parameter_file(tmp_path, capsys):
    params = tmp_path / "params.yaml"
    params.write_text("preset: cartesian\nestimation_rate: 20\n")
    assert main(["ros", "--params", str(params), "--preset", "franka"]) == 2
    assert "needs a point-mass model" in capsys.readouterr().err
    assert main(["ros", "--preset", "arm", "--estimation-rate", "-250"]) == 2
    assert capsys.readouterr().err.strip() == "comanip ros: error: estimation_rate must be a finite number > 0 (Hz), got -250.0"


def test_the_ros_guides_franka_parameters_are_valid(tmp_path):
    readme = (Path(__file__).resolve().parents[2] / "docs" / "guide" / "ros.md").read_text()
    block = readme.split("```yaml\ncomanip_goal:", 1)[1].split("```", 1)[0]
    params = tmp_path / "franka.yaml"
    params.write_text("comanip_goal:" + block)
    settings = NodeSettings.from_yaml(params)
    assert settings.frame_id == "fr3_link0" and settings.equilibrium_topic.endswith("/equilibrium_pose")


def test_the_example_node_config_is_valid():
    settings = NodeSettings.from_yaml(Path(__file__).resolve().parents[2] / "examples" / "data" / "node.yaml")
    assert settings.preset == "cartesian" and settings.prior_goal == (0.4, 0.1, 0.1)

"""The ROS interface package templates render, build with the wheels' CMake packages and work.

The build goes into a temporary prefix (not the venv) so the tests also prove that
ros_runtime_env is enough to use a package installed elsewhere.
"""

from __future__ import annotations

import importlib.util
import json
import os
import shutil
import subprocess
import sys
import textwrap
import time
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import jinja2
import pytest

from sam_codegen.project.ros_install import (
    RosBuildError,
    build_ros_package,
    is_installed,
    ros_packages_in_order,
    ros_runtime_env,
)

TEMPLATES = Path(__file__).resolve().parents[2] / "templates" / "ros"
PKG = "samtest_msgs"

# The nested message refers to the other one of the same package, which rosidl must order itself.
MSG_FILES = {
    "Reading": textwrap.dedent(
        """\
        std_msgs/Header header
        int32 count
        float32[<=4] values
        """
    ),
    "Status": textwrap.dedent(
        """\
        uint8 MODE_A=1
        uint8 mode
        string label
        Reading reading
        """
    ),
}


@dataclass(frozen=True)
class PackageInfo:
    name: str
    version: str = "0.3.1"
    description: str = "Test <messages> & \"quotes\" for 'sam'"
    maintainer: str = "SAM <team> & co"
    maintainer_email: str = "sam@example.com"
    license: str = "MIT"


def _environment() -> jinja2.Environment:
    # The same settings the code generator uses.
    return jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(TEMPLATES)),
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
        undefined=jinja2.StrictUndefined,
        autoescape=False,
    )


def _render_package(
    dest: Path, msgs: dict[str, str], dependencies: list[str], name: str = PKG
) -> dict[str, str]:
    env = _environment()
    context = {"package": PackageInfo(name), "messages": sorted(msgs), "dependencies": sorted(dependencies)}
    rendered = {
        "CMakeLists.txt": env.get_template("CMakeLists.txt.j2").render(**context),
        "package.xml": env.get_template("package.xml.j2").render(**context),
    }
    (dest / "msg").mkdir(parents=True, exist_ok=True)
    for filename, text in rendered.items():
        (dest / filename).write_text(text)
    for msg_name, text in msgs.items():
        (dest / "msg" / f"{msg_name}.msg").write_text(text)
    return rendered


def _missing_build_tools() -> str | None:
    if shutil.which("cmake") is None:
        return "cmake is not installed"
    if importlib.util.find_spec("rclpy") is None:
        return "rclpy is not installed (pip extra 'runtime')"
    if not (Path(sys.prefix) / "share" / "rosidl_default_generators" / "package.xml").is_file():
        return "rosidl_default_generators is not installed in this environment (pip extra 'rosbuild')"
    return None


needs_ros_build = pytest.mark.skipif(_missing_build_tools() is not None, reason=str(_missing_build_tools()))


# --- fast checks of the templates and the helpers (no CMake) ---------------------------------


def test_templates_render_valid_escaped_package_xml(tmp_path: Path) -> None:
    rendered = _render_package(tmp_path, MSG_FILES, ["std_msgs"])
    root = ET.fromstring(rendered["package.xml"])
    assert root.get("format") == "3"
    assert root.findtext("name") == PKG
    assert root.findtext("description") == PackageInfo(PKG).description
    assert root.findtext("maintainer") == PackageInfo(PKG).maintainer
    assert [e.text for e in root.findall("depend")] == ["std_msgs"]
    assert {e.text for e in root.findall("buildtool_depend")} == {"ament_cmake", "rosidl_default_generators"}
    assert root.findtext("exec_depend") == "rosidl_default_runtime"
    assert root.findtext("member_of_group") == "rosidl_interface_packages"
    assert root.findtext("export/build_type") == "ament_cmake"

    cmake = rendered["CMakeLists.txt"]
    assert f"project({PKG})" in cmake
    assert '"msg/Reading.msg"\n  "msg/Status.msg"\n  DEPENDENCIES std_msgs\n)' in cmake
    assert "find_package(std_msgs REQUIRED)" in cmake
    # The wheel workaround must run before the generators create targets that link the broken ones.
    assert cmake.index("IMPORTED_TARGETS") < cmake.index("rosidl_generate_interfaces(")


def test_templates_are_deterministic_and_handle_no_dependencies(tmp_path: Path) -> None:
    msgs = {"Plain": "int32 a\n"}
    first = _render_package(tmp_path / "a", msgs, [])
    second = _render_package(tmp_path / "b", msgs, [])
    assert first == second
    assert "DEPENDENCIES" not in first["CMakeLists.txt"]
    assert ET.fromstring(first["package.xml"]).findall("depend") == []


def test_ros_runtime_env_prepends_prefix(tmp_path: Path) -> None:
    base = {"PYTHONPATH": "/x", "LD_LIBRARY_PATH": "/y", "AMENT_PREFIX_PATH": "/z"}
    env = ros_runtime_env(tmp_path, base)
    site = tmp_path / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}" / "site-packages"
    assert env["PYTHONPATH"].split(":")[:2] == [str(site), "/x"]
    assert env["LD_LIBRARY_PATH"].split(":")[:2] == [str(tmp_path / "lib"), "/y"]
    assert env["AMENT_PREFIX_PATH"].split(":")[:2] == [str(tmp_path), "/z"]
    assert env["ROS_AUTOMATIC_DISCOVERY_RANGE"] == "LOCALHOST"
    assert base == {"PYTHONPATH": "/x", "LD_LIBRARY_PATH": "/y", "AMENT_PREFIX_PATH": "/z"}
    # A caller's explicit choice wins.
    explicit = ros_runtime_env(tmp_path, {"ROS_AUTOMATIC_DISCOVERY_RANGE": "OFF"})
    assert explicit["ROS_AUTOMATIC_DISCOVERY_RANGE"] == "OFF"


def test_is_installed(tmp_path: Path) -> None:
    assert not is_installed(PKG, tmp_path)
    (tmp_path / "share" / PKG).mkdir(parents=True)
    (tmp_path / "share" / PKG / "package.xml").write_text("<package/>")
    assert is_installed(PKG, tmp_path)


def test_missing_cmake_is_a_readable_error(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(shutil, "which", lambda _name: None)
    with pytest.raises(RosBuildError, match="cmake was not found"):
        build_ros_package(tmp_path, tmp_path / "build", tmp_path / "install")


# --- real builds ------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def built_prefix(tmp_path_factory: pytest.TempPathFactory) -> Path:
    if (reason := _missing_build_tools()) is not None:
        pytest.skip(reason)
    root = tmp_path_factory.mktemp("ros_build")
    _render_package(root / "src" / PKG, MSG_FILES, ["std_msgs"])
    start = time.monotonic()
    build_ros_package(root / "src" / PKG, root / "build", root / "install")
    # Shown with -s / on failure: the notes promise ~10 s and a regression should be visible.
    print(f"built {PKG} in {time.monotonic() - start:.1f} s")
    return root / "install"


@pytest.mark.ros
@pytest.mark.slow
@needs_ros_build
def test_build_installs_package(built_prefix: Path) -> None:
    assert is_installed(PKG, built_prefix)
    py_version = f"python{sys.version_info.major}.{sys.version_info.minor}"
    assert (built_prefix / "lib" / py_version / "site-packages" / PKG / "msg" / "__init__.py").is_file()
    assert (built_prefix / "share" / PKG / "msg" / "Status.msg").is_file()


# Runs in a subprocess: the loader only honours LD_LIBRARY_PATH set before the process starts.
_ROUNDTRIP_SCRIPT = textwrap.dedent(
    """\
    import json
    import os
    import time

    # Fast DDS must not send discovery traffic off the machine (loopback only here).
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"

    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.serialization import deserialize_message, serialize_message

    from {pkg}.msg import Reading, Status

    result = {{}}
    msg = Status(mode=Status.MODE_A, label="ballast <&> ok")
    msg.reading.header.frame_id = "sam/base_link"
    msg.reading.header.stamp.sec = 12
    msg.reading.header.stamp.nanosec = 345
    msg.reading.count = -7
    msg.reading.values = [1.5, -2.25, 3.0]
    result["mode_a"] = Status.MODE_A
    try:
        # Jazzy checks field values only on request (check_fields / ROS_PYTHON_CHECK_FIELDS=1).
        Reading(check_fields=True, values=[0.0] * 5)
        result["bound_enforced"] = False
    except AssertionError:
        result["bound_enforced"] = True

    data = serialize_message(msg)
    result["serialized_len"] = len(data)
    result["deserialize_equal"] = deserialize_message(data, Status) == msg

    rclpy.init()
    try:
        talker = rclpy.create_node("samtest_talker")
        listener = rclpy.create_node("samtest_listener")
        received = []
        topic = "/samtest/status_{pid}"
        listener.create_subscription(Status, topic, received.append, 10)
        pub = talker.create_publisher(Status, topic, 10)
        executor = SingleThreadedExecutor()
        executor.add_node(talker)
        executor.add_node(listener)

        deadline = time.monotonic() + 10.0
        while pub.get_subscription_count() == 0 and time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.02)
        result["matched"] = pub.get_subscription_count() > 0
        # Publishing again on each turn covers the window between matching and the reader being ready.
        while not received and time.monotonic() < deadline:
            pub.publish(msg)
            executor.spin_once(timeout_sec=0.1)
        result["received"] = len(received) > 0
        result["received_equal"] = bool(received) and received[0] == msg
        result["topic_types"] = dict(talker.get_topic_names_and_types()).get(topic)
        executor.shutdown()
        talker.destroy_node()
        listener.destroy_node()
    finally:
        rclpy.shutdown()
    print("RESULT " + json.dumps(result))
    """
)


@pytest.mark.ros
@pytest.mark.slow
@needs_ros_build
def test_import_serialize_and_pubsub_roundtrip(built_prefix: Path, tmp_path: Path) -> None:
    script = tmp_path / "roundtrip.py"
    script.write_text(_ROUNDTRIP_SCRIPT.format(pkg=PKG, pid=os.getpid()))
    proc = subprocess.run(
        [sys.executable, str(script)],
        env=ros_runtime_env(built_prefix),
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    lines = [line for line in proc.stdout.splitlines() if line.startswith("RESULT ")]
    assert lines, proc.stdout + proc.stderr
    result = json.loads(lines[-1].removeprefix("RESULT "))
    assert result["mode_a"] == 1
    assert result["bound_enforced"] is True
    assert result["serialized_len"] > 0
    assert result["deserialize_equal"] is True
    assert result["matched"] is True, "no subscription matched within 10 s"
    assert result["received"] is True, "nothing received within 10 s"
    assert result["received_equal"] is True
    assert result["topic_types"] == [f"{PKG}/msg/Status"]


@pytest.mark.ros
@pytest.mark.slow
@needs_ros_build
def test_broken_msg_raises_ros_build_error(tmp_path: Path) -> None:
    broken = {"Broken": "int32 fine\nfloat33 not_a_type\n"}
    _render_package(tmp_path / "src", broken, [], name="samtest_broken_msgs")
    with pytest.raises(RosBuildError) as excinfo:
        build_ros_package(tmp_path / "src", tmp_path / "build", tmp_path / "install")
    text = str(excinfo.value)
    assert "configure failed" in text
    assert "float33" in text
    assert not is_installed("samtest_broken_msgs", tmp_path / "install")


def test_a_package_without_messages_is_not_built(tmp_path: Path) -> None:
    """A spec whose ROS side uses upstream messages only (the ferry, its device duties off: their default srvs would
    be the package's) generates its own package empty: rosidl would refuse it ("called without any interface
    files"), so ros-install leaves it out and says so."""
    from sam_codegen.cli import main
    from sam_codegen.frontend.loader import load_spec_file
    from sam_codegen.project.ros_install import has_interfaces
    from sam_codegen.targets.ros import emit
    from sam_codegen.validate.resolve import validate

    ferry = (Path(__file__).parents[1] / "specs" / "ferry.yaml").read_text(encoding="utf-8")
    assert ferry.count("bridge:\n") == 1
    spec = tmp_path / "ferry.yaml"
    spec.write_text(ferry.replace("bridge:\n", "bridge:\n  node_services: false\n"), encoding="utf-8")
    resolved = validate(load_spec_file(spec))
    assert not resolved.messages and not resolved.services
    for rel, text in emit(resolved).items():
        (tmp_path / "generated" / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / "generated" / rel).write_text(text)
    own = tmp_path / "generated" / "ros" / resolved.spec.ros.name
    assert (own / "package.xml").is_file() and not has_interfaces(own)
    assert ros_packages_in_order(tmp_path / "generated" / "ros") == []  # (the ferry needs no other package either)
    assert main(["ros-install", "--out", str(tmp_path / "generated")]) == 0  # says so; no CMake run


_CONSTANTS_ONLY_SCRIPT = textwrap.dedent(
    """\
    import json

    from rclpy.serialization import deserialize_message, serialize_message

    from buoy_msgs.msg import Topics

    msg = Topics()
    roundtrip = deserialize_message(serialize_message(msg), Topics) == msg
    print("RESULT " + json.dumps({"level": Topics.LEVEL, "roundtrip": roundtrip}))
    """
)


@pytest.mark.ros
@pytest.mark.slow
@needs_ros_build
def test_a_constants_only_message_builds_and_imports(tmp_path: Path) -> None:
    """A message of constants only (a vehicle's Topics.msg of topic names, issue 19): rosidl builds it (its C/C++
    generators add a placeholder member), and Python reads the constant and serializes the empty message."""
    from sam_codegen.build import generate

    base = (Path(__file__).parents[1] / "specs" / "minimal.yaml").read_text(encoding="utf-8")
    spec = tmp_path / "minimal.yaml"
    # (catkin_pkg refuses a package.xml without a description, which minimal.yaml does not give)
    text = base.replace("ros: {package: buoy_msgs}", "ros: {package: buoy_msgs, description: Test buoy.}", 1)
    spec.write_text(text.replace("messages:\n", "messages:\n  Topics:\n    description: Topic names.\n    constants:\n"
                                 "      - {name: LEVEL, type: string, value: /level}\n", 1), encoding="utf-8")
    files = generate(spec)
    assert files["ros/buoy_msgs/msg/Topics.msg"].endswith('\n\nstring LEVEL="/level"\n')  # (no blank line after it)
    for rel, text in files.items():
        if rel.startswith("ros/"):
            (tmp_path / "generated" / rel).parent.mkdir(parents=True, exist_ok=True)
            (tmp_path / "generated" / rel).write_text(text, encoding="utf-8")
    prefix = tmp_path / "install"
    build_ros_package(tmp_path / "generated" / "ros" / "buoy_msgs", tmp_path / "build", prefix)
    script = tmp_path / "constants_only.py"
    script.write_text(_CONSTANTS_ONLY_SCRIPT)
    proc = subprocess.run([sys.executable, str(script)], env=ros_runtime_env(prefix), capture_output=True, text=True,
                          timeout=60, check=False)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    lines = [line for line in proc.stdout.splitlines() if line.startswith("RESULT ")]
    assert lines, proc.stdout + proc.stderr
    assert json.loads(lines[-1].removeprefix("RESULT ")) == {"level": "/level", "roundtrip": True}

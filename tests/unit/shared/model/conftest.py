"""The paper's two parameter sets as joint configs and model constants."""

from __future__ import annotations

import pytest

from shared.config import JointConfig, load_joint
from shared.model import JointConstants
from tests.support.paths import JOINTS as JOINTS_FOLDER

JOINTS = JOINTS_FOLDER


@pytest.fixture
def joint_5_2() -> JointConfig:
    return load_joint(JOINTS / "paper-section-5-2.toml")


@pytest.fixture
def joint_3_4() -> JointConfig:
    return load_joint(JOINTS / "paper-section-3-4.toml")


@pytest.fixture
def constants_5_2(joint_5_2: JointConfig) -> JointConstants:
    return JointConstants.of(joint_5_2)

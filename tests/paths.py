"""Where tests find the repository's files and the team handbook's data."""

from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
CONFIG = REPO / "config"
STATION_FILE = CONFIG / "station.toml"
DBC_FILE = CONFIG / "can" / "station.dbc"
JOINT_5_2 = CONFIG / "joints" / "paper-section-5-2.toml"
#: ../shared beside the checkout (CI puts it there); never copied into the project.
HANDBOOK_DATA = REPO.parent / "shared" / "data"
#: real controller runs shipped with the project (tests/data/cs351-real-runs/README.md)
PROJECT_REAL_RUNS = REPO / "tests" / "data" / "cs351-real-runs"
#: the ten real runs of the handbook, a wider check when ../shared is there
HANDBOOK_REAL_RUNS = HANDBOOK_DATA / "cs351-real-runs"

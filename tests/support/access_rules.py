"""Reading a zenoh ``access_control`` section: which key expressions a common name may put."""

from __future__ import annotations

from typing import Any


def put_keys_granted(acl: dict[str, Any], common_name: str) -> set[str]:
    """Key expressions ``common_name`` may put into the router (ingress), by the ACL."""
    subjects = {s["id"] for s in acl["subjects"] if common_name in s["cert_common_names"]}
    rules = {rule["id"]: rule for rule in acl["rules"]}
    granted: set[str] = set()
    for policy in acl["policies"]:
        if subjects & set(policy["subjects"]):
            for rule in (rules[r] for r in policy["rules"]):
                if "put" in rule["messages"] and "ingress" in rule["flows"]:
                    granted |= set(rule["key_exprs"])
    return granted


def common_names(acl: dict[str, Any]) -> set[str]:
    """Every certificate common name the ACL knows."""
    return {name for subject in acl["subjects"] for name in subject["cert_common_names"]}

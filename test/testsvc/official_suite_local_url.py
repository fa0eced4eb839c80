"""pytest plugin for official_suite.py, rr+local only: the official suite adds `?service=NAME` to
ROBOTRACONTEUR_TEST_SERVER_URL even when that URL already has a query, and an rr+local URL always has
one (`rr+local:///?nodename=NAME`: the node must be named), so every rr+local run of the unmodified
suite fails with "Invalid Connection URL", against any service. This joins with `&` instead."""
from RobotRaconteurTest import service_test_util as _stu

_original = _stu.TestServerNodeConfig.get_service_url


def _get_service_url(self, service_name):
    if self.node_setup is None and "?" in self.node_endpoint_url:
        return self.node_endpoint_url + "&service=" + service_name
    return _original(self, service_name)


_stu.TestServerNodeConfig.get_service_url = _get_service_url

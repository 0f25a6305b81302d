"""Cells on a shared network: mutual TLS and user/password authentication through
``--zenoh-config`` files (the recipe of docs/session.md), with a throwaway CA.

Real processes: an ``executor serve`` cell and this test's planner-side Zenoh session.
A planner with a certificate signed by the CA is served; a peer without a certificate
cannot join; a cell without the credentials cannot show itself to the planner, nor can a
user with credentials whom the access-control rules do not allow (each such cell a Zenoh
session of the test's process with its config, declaring a cell's token: what keeps it out
is its config, not its process, and a cell process's start is 2.4 s of CPU of imports).
"""

from __future__ import annotations

import datetime
import ipaddress
from pathlib import Path

import pytest
from cryptography import x509
from cryptography.hazmat.primitives import hashes, serialization
from cryptography.hazmat.primitives.asymmetric import ec
from cryptography.x509.oid import NameOID

from asp.session.cells import CellProcess, start_cell
from bridge.cell_settings import ServeSettings
from bridge.client import CellDirectory, CellTimeout, request_insert
from bridge.keys import alive_key
from bridge.messages import InsertRequest
from bridge.session import free_loopback_endpoint, open_session

pytestmark = [pytest.mark.slow, pytest.mark.timeout(120)]
KEPT_OUT_S = 2.0
"""[s] how long a peer that must not get in is watched for, after its session opened and
declared its token: a token reaches a connected peer within milliseconds
(docs/decisions.md, ``bench mesh``)."""


def _name(common_name: str) -> x509.Name:
    return x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, common_name)])


def _write(folder: Path, stem: str, key: ec.EllipticCurvePrivateKey, cert: x509.Certificate) -> None:
    (folder / f"{stem}.key").write_bytes(key.private_bytes(
        serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8, serialization.NoEncryption()))
    (folder / f"{stem}.pem").write_bytes(cert.public_bytes(serialization.Encoding.PEM))


def make_certificates(folder: Path) -> None:
    """``ca.pem`` and, signed by it, ``cell.{pem,key}`` and ``planner.{pem,key}`` for localhost."""
    now = datetime.datetime.now(datetime.UTC)
    valid = (now - datetime.timedelta(minutes=5), now + datetime.timedelta(days=1))
    ca_key = ec.generate_private_key(ec.SECP256R1())
    ca = (x509.CertificateBuilder().subject_name(_name("throwaway ca")).issuer_name(_name("throwaway ca"))
          .public_key(ca_key.public_key()).serial_number(x509.random_serial_number())
          .not_valid_before(valid[0]).not_valid_after(valid[1])
          .add_extension(x509.BasicConstraints(ca=True, path_length=None), critical=True)
          .sign(ca_key, hashes.SHA256()))
    _write(folder, "ca", ca_key, ca)
    names = x509.SubjectAlternativeName([x509.DNSName("localhost"), x509.IPAddress(ipaddress.ip_address("127.0.0.1"))])
    for stem in ("cell", "planner"):
        key = ec.generate_private_key(ec.SECP256R1())
        cert = (x509.CertificateBuilder().subject_name(_name("localhost")).issuer_name(ca.subject)
                .public_key(key.public_key()).serial_number(x509.random_serial_number())
                .not_valid_before(valid[0]).not_valid_after(valid[1]).add_extension(names, critical=False)
                .sign(ca_key, hashes.SHA256()))
        _write(folder, stem, key, cert)


def tls_config(folder: Path, side: str, endpoint: str, certificate: bool = True) -> Path:
    """A JSON5 Zenoh config: the cell listens on ``endpoint``, the planner connects to it."""
    direction = "listen" if side == "cell" else "connect"
    own = (f'{direction}_private_key: "{folder}/{side}.key", {direction}_certificate: "{folder}/{side}.pem", '
           "enable_mtls: true,") if certificate else ""
    path = folder / f"{side}{'' if certificate else '-nocert'}.json5"
    path.write_text(f"""{{
  mode: "peer",
  scouting: {{ multicast: {{ enabled: false }} }},
  {direction}: {{ endpoints: ["{endpoint}"] }},
  transport: {{ link: {{ tls: {{ root_ca_certificate: "{folder}/ca.pem", {own} }} }} }},
}}
""")
    return path


ACCESS_RULES = (
    'access_control: { enabled: true, default_permission: "deny", rules: [{ id: "cells", '
    'permission: "allow", flows: ["ingress", "egress"], key_exprs: ["cell/**"], messages: ["query", '
    '"reply", "declare_queryable", "liveliness_token", "declare_subscriber", "liveliness_query", '
    '"declare_liveliness_subscriber"] }], subjects: [{ id: "cell-users", usernames: ["cell"] }], '
    'policies: [{ rules: ["cells"], subjects: ["cell-users"] }] },')
"""The access-control rules of docs/session.md: only user ``cell`` may use ``cell/**``."""


def userpwd_config(folder: Path, name: str, listen: str, user: str | None, rules: str = "") -> Path:
    """A JSON5 Zenoh config with user/password authentication against ``users.txt`` (users
    ``cell`` and ``visitor``), and optional access-control ``rules``."""
    (folder / "users.txt").write_text("cell:s3cret\nvisitor:s3cret\n")
    auth = f'user: "{user}", password: "s3cret", ' if user else ""
    path = folder / f"{name}.json5"
    path.write_text(f"""{{
  mode: "peer",
  scouting: {{ multicast: {{ enabled: false }} }},
  listen: {{ endpoints: [{f'"{listen}"' if listen else ""}] }},
  transport: {{ auth: {{ usrpwd: {{ {auth}dictionary_file: "{folder}/users.txt" }} }} }},
  {rules}
}}
""")
    return path




def test_mutual_tls_serves_a_certified_planner_and_keeps_out_a_peer_without_certificate(
        tmp_path: Path, cells: list[CellProcess]) -> None:
    make_certificates(tmp_path)
    endpoint = free_loopback_endpoint().replace("tcp/127.0.0.1", "tls/localhost")
    cells.append(start_cell(ServeSettings(cell_id="c1", backend="truth",
                                          zenoh_config=str(tls_config(tmp_path, "cell", endpoint)))))
    for config, served in ((tls_config(tmp_path, "planner", endpoint), True),
                           (tls_config(tmp_path, "planner", endpoint, certificate=False), False)):
        session = open_session(config_file=config)
        directory = CellDirectory(session)
        try:
            if served:
                directory.wait_for(1, timeout=20)
                assert request_insert(session, "c1", InsertRequest(id="tls1", part="sh", hole="br"), 10).result == "fit"
            else:
                with pytest.raises(CellTimeout):
                    directory.wait_for(1, timeout=KEPT_OUT_S)
        finally:
            directory.close()
            session.close()


def _only_c1_is_served(cells: list[CellProcess], endpoint: str, planner: Path, cell: Path, other: str,
                       other_config: Path, request_id: str) -> None:
    """With the planner's Zenoh config ``planner``, cell ``c1`` (config ``cell``, an
    ``executor serve`` process) answers; ``other``, a Zenoh session of this process with the
    config ``other_config`` that declares the token a cell shows itself by (``cell/OTHER/alive``,
    as ``executor serve`` does once its session is open), never shows itself to the planner."""
    session = open_session(config_file=planner)
    directory = CellDirectory(session)
    try:
        cells.append(start_cell(ServeSettings(cell_id="c1", backend="truth", connect=(endpoint,),
                                              zenoh_config=str(cell))))
        rogue = open_session(connect=(endpoint,), config_file=other_config)
        try:
            token = rogue.liveliness().declare_token(alive_key(other))
            directory.wait_for(1, timeout=20)
            assert request_insert(session, "c1", InsertRequest(id=request_id, part="p1", hole="r1"),
                                  10).result == "fit"
            with pytest.raises(CellTimeout):
                directory.wait_for(2, timeout=KEPT_OUT_S)
            assert directory.alive() == {"c1"}
            token.undeclare()
        finally:
            rogue.close()
    finally:
        directory.close()
        session.close()


def test_a_cell_without_the_credentials_cannot_show_itself_to_the_planner(
        tmp_path: Path, cells: list[CellProcess]) -> None:
    endpoint = free_loopback_endpoint()
    _only_c1_is_served(cells, endpoint, userpwd_config(tmp_path, "planner", endpoint, user=None),
                       userpwd_config(tmp_path, "cell", "", user="cell"),
                       "evil", userpwd_config(tmp_path, "rogue", "", user=None), "auth1")


def test_access_control_lets_only_authorised_users_serve_cells(tmp_path: Path, cells: list[CellProcess]) -> None:
    """Both users know a password; only ``cell`` may declare ``cell/**`` (the docs' rules)."""
    endpoint = free_loopback_endpoint()
    _only_c1_is_served(cells, endpoint, userpwd_config(tmp_path, "planner", endpoint, "cell", ACCESS_RULES),
                       userpwd_config(tmp_path, "cell", "", "cell"),
                       "visitor", userpwd_config(tmp_path, "visitor", "", "visitor"), "acl1")

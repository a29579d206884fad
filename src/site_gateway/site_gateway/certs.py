"""The sites' CA, and each site's key and certificate, for the gateways' mutual TLS.

    haptic_certs init DIR                               # DIR/ca.pem, DIR/ca.key
    haptic_certs issue DIR operator|remote [--host H]   # DIR/<role>.pem, DIR/<role>.key

Why a CA of the sites' own: each gateway trusts this CA only, so a certificate from anywhere
else (a public CA, another project's) opens no session. A certificate's common name is its
site's role, which the access control reads (``zenoh_config.access_control``). The remote
site's certificate names the hosts the operator dials (``--host``, repeatable; default
``localhost`` and ``127.0.0.1``), which the operator's gateway checks.

Keys are EC P-256, written readable by their owner only (0600), and never overwritten: an
existing file stops the command, so that no key in use is lost. Keep ``ca.key`` off both
sites; copy ``ca.pem`` and one site's ``<role>.pem`` and ``<role>.key`` to that site.
"""
import argparse
import datetime
import ipaddress
import os
from pathlib import Path
import sys

from cryptography import x509
from cryptography.hazmat.primitives import hashes, serialization
from cryptography.hazmat.primitives.asymmetric import ec
from cryptography.x509.oid import ExtendedKeyUsageOID, NameOID

from site_gateway.routes import ROLES

__all__ = ['CA_DAYS', 'SITE_DAYS', 'init_ca', 'issue', 'main']

CA_DAYS = 3650
SITE_DAYS = 825  # the longest a TLS client accepts for a leaf certificate
CA_NAME = 'haptic sites CA'
DEFAULT_HOSTS = ('localhost', '127.0.0.1')


def _now() -> datetime.datetime:
    return datetime.datetime.now(datetime.timezone.utc)


def _write(path: Path, data: bytes, mode: int) -> None:
    """Write a new file with ``mode`` from its creation on; an existing one raises."""
    descriptor = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, mode)
    with os.fdopen(descriptor, 'wb') as file:
        file.write(data)


def _write_pair(directory: Path, stem: str, key, certificate: x509.Certificate) -> None:
    for path in (directory / f'{stem}.key', directory / f'{stem}.pem'):
        if path.exists():
            raise FileExistsError(f'{path} exists already; nothing was written (remove it '
                                  f'first to make a new one)')
    _write(directory / f'{stem}.key', key.private_bytes(
        serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8,
        serialization.NoEncryption()), 0o600)
    _write(directory / f'{stem}.pem', certificate.public_bytes(serialization.Encoding.PEM),
           0o644)


def _builder(subject: str, issuer: x509.Name, public_key, days: int) -> x509.CertificateBuilder:
    now = _now()
    return (x509.CertificateBuilder()
            .subject_name(x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, subject)]))
            .issuer_name(issuer).public_key(public_key)
            .serial_number(x509.random_serial_number())
            .not_valid_before(now - datetime.timedelta(minutes=5))
            .not_valid_after(now + datetime.timedelta(days=days)))


def init_ca(directory) -> Path:
    """Make the sites' CA in ``directory`` (created if need be); return its certificate."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    key = ec.generate_private_key(ec.SECP256R1())
    name = x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, CA_NAME)])
    usage = x509.KeyUsage(digital_signature=True, key_cert_sign=True, crl_sign=True,
                          content_commitment=False, key_encipherment=False,
                          data_encipherment=False, key_agreement=False, encipher_only=False,
                          decipher_only=False)
    certificate = (_builder(CA_NAME, name, key.public_key(), CA_DAYS)
                   .add_extension(x509.BasicConstraints(ca=True, path_length=0), critical=True)
                   .add_extension(usage, critical=True)
                   .add_extension(x509.SubjectKeyIdentifier.from_public_key(key.public_key()),
                                  critical=False)
                   .sign(key, hashes.SHA256()))
    _write_pair(directory, 'ca', key, certificate)
    return directory / 'ca.pem'


def _alternative_name(host: str) -> x509.GeneralName:
    try:
        return x509.IPAddress(ipaddress.ip_address(host))
    except ValueError:
        return x509.DNSName(host)


def issue(directory, role: str, hosts=DEFAULT_HOSTS) -> Path:
    """Issue ``role``'s key and certificate from the CA in ``directory``; return the latter.

    ``hosts`` (names or addresses) are what the other site dials to reach this one.
    """
    if role not in ROLES:
        raise ValueError(f'role {role!r} is not one of {list(ROLES)}')
    directory = Path(directory)
    try:
        ca_key = serialization.load_pem_private_key((directory / 'ca.key').read_bytes(), None)
        ca = x509.load_pem_x509_certificate((directory / 'ca.pem').read_bytes())
    except FileNotFoundError as error:
        raise FileNotFoundError(f'{error.filename} is missing: run haptic_certs init '
                                f'{directory} first') from None
    key = ec.generate_private_key(ec.SECP256R1())
    certificate = (_builder(role, ca.subject, key.public_key(), SITE_DAYS)
                   .add_extension(x509.BasicConstraints(ca=False, path_length=None),
                                  critical=True)
                   .add_extension(x509.SubjectAlternativeName(
                       [_alternative_name(host) for host in (hosts or DEFAULT_HOSTS)]),
                       critical=False)
                   .add_extension(x509.ExtendedKeyUsage([ExtendedKeyUsageOID.SERVER_AUTH,
                                                         ExtendedKeyUsageOID.CLIENT_AUTH]),
                                  critical=False)
                   .add_extension(x509.AuthorityKeyIdentifier.from_issuer_public_key(
                       ca.public_key()), critical=False)
                   .sign(ca_key, hashes.SHA256()))
    _write_pair(directory, role, key, certificate)
    return directory / f'{role}.pem'


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog='haptic_certs', description=__doc__.split('\n\n')[0])
    commands = parser.add_subparsers(dest='command', required=True)
    commands.add_parser('init', help='make the sites\' CA').add_argument('directory')
    issuing = commands.add_parser('issue', help='make one site\'s key and certificate')
    issuing.add_argument('directory')
    issuing.add_argument('role', choices=ROLES)
    issuing.add_argument('--host', action='append', dest='hosts', metavar='NAME_OR_ADDRESS',
                         help='a host the other site dials to reach this one (repeatable; '
                         f'default: {", ".join(DEFAULT_HOSTS)})')
    args = parser.parse_args(argv)
    try:
        if args.command == 'init':
            written = init_ca(args.directory)
        else:
            written = issue(args.directory, args.role, args.hosts)
    except (OSError, ValueError) as error:
        print(f'haptic_certs: {error}', file=sys.stderr)
        return 1
    print(f'haptic_certs: wrote {written} and its key {written.with_suffix(".key")} (0600)')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())

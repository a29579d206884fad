"""haptic_certs: a CA, and each site's key and certificate, checked by OpenSSL itself."""
import os
import shutil
import stat
import subprocess

from cryptography import x509
from cryptography.x509.oid import NameOID
import pytest

from site_gateway.certs import init_ca, issue, main

pytestmark = pytest.mark.skipif(shutil.which('openssl') is None, reason='needs openssl')


def mode(path) -> int:
    return stat.S_IMODE(os.stat(path).st_mode)


def verify(ca, certificate) -> subprocess.CompletedProcess:
    return subprocess.run(['openssl', 'verify', '-CAfile', str(ca), '-purpose', 'sslserver',
                           str(certificate)], capture_output=True, text=True)


def test_init_and_issue_make_a_chain_openssl_accepts_with_private_keys(tmp_path):
    assert main(['init', str(tmp_path / 'ca')]) == 0
    assert main(['issue', str(tmp_path / 'ca'), 'remote', '--host', 'remote.example.org',
                 '--host', '192.0.2.2']) == 0
    assert main(['issue', str(tmp_path / 'ca'), 'operator']) == 0
    folder = tmp_path / 'ca'
    for stem in ('ca', 'remote', 'operator'):
        assert mode(folder / f'{stem}.key') == 0o600
        assert mode(folder / f'{stem}.pem') == 0o644
    for role in ('remote', 'operator'):
        assert verify(folder / 'ca.pem', folder / f'{role}.pem').returncode == 0
    certificate = x509.load_pem_x509_certificate((folder / 'remote.pem').read_bytes())
    assert certificate.subject.get_attributes_for_oid(NameOID.COMMON_NAME)[0].value == 'remote'
    names = certificate.extensions.get_extension_for_class(x509.SubjectAlternativeName).value
    assert names.get_values_for_type(x509.DNSName) == ['remote.example.org']
    assert [str(a) for a in names.get_values_for_type(x509.IPAddress)] == ['192.0.2.2']
    operator = x509.load_pem_x509_certificate((folder / 'operator.pem').read_bytes())
    names = operator.extensions.get_extension_for_class(x509.SubjectAlternativeName).value
    assert names.get_values_for_type(x509.DNSName) == ['localhost']


def test_a_certificate_of_another_ca_does_not_verify(tmp_path):
    init_ca(tmp_path / 'a')
    init_ca(tmp_path / 'b')
    issue(tmp_path / 'b', 'operator')
    assert verify(tmp_path / 'a' / 'ca.pem', tmp_path / 'b' / 'operator.pem').returncode != 0


def test_nothing_is_overwritten_and_a_missing_ca_is_named(tmp_path, capsys):
    init_ca(tmp_path)
    issue(tmp_path, 'operator')
    key = (tmp_path / 'operator.key').read_bytes()
    assert main(['issue', str(tmp_path), 'operator']) == 1
    assert 'exists already' in capsys.readouterr().err
    assert (tmp_path / 'operator.key').read_bytes() == key
    assert main(['init', str(tmp_path)]) == 1
    assert main(['issue', str(tmp_path / 'none'), 'remote']) == 1
    assert 'haptic_certs init' in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(['issue', str(tmp_path), 'pilot'])

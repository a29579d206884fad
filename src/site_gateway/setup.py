from glob import glob

from setuptools import find_packages, setup

package_name = 'site_gateway'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/config', glob('config/*')),
    ],
    install_requires=['setuptools', 'eclipse-zenoh', 'cryptography'],
    zip_safe=False,
    maintainer='Haptic toolkit maintainers',
    maintainer_email='maintainers@haptic-telesono.invalid',
    description='One site of telerobotic ultrasound joined to the other over Zenoh, with mutual '
                'TLS and access control by certificate.',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'site_gateway = site_gateway.gateway:main',
            'haptic_certs = site_gateway.certs:main',
        ],
    },
)

from glob import glob

from setuptools import find_packages, setup

package_name = 'haptic_wand_driver'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/config', glob('config/*.yaml')),
    ],
    install_requires=['setuptools', 'numpy', 'rosbags'],
    zip_safe=False,
    maintainer='Haptic toolkit maintainers',
    maintainer_email='maintainers@haptic-telesono.invalid',
    description='5-DOF haptic wand driver: a device interface, a simulated wand, and replay.',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'wand_driver = haptic_wand_driver.node:main',
        ],
    },
)

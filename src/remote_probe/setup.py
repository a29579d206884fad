from glob import glob

from setuptools import find_packages, setup

package_name = 'remote_probe'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/config', glob('config/*')),
    ],
    install_requires=['setuptools', 'numpy'],
    extras_require={'phantom': ['trimesh']},
    zip_safe=False,
    maintainer='Haptic toolkit maintainers',
    maintainer_email='maintainers@haptic-telesono.invalid',
    description='Telerobotic ultrasound: the remote robot probe, its patient, the link, and both '
                'ends of the bilateral schemes.',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'make_phantom = remote_probe.phantom:main',
            'sim_robot = remote_probe.robot_node:main',
            'teleop_follower = remote_probe.follower_node:main',
            'teleop_leader = remote_probe.leader_node:main',
        ],
    },
)

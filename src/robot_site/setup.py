from glob import glob

from setuptools import find_packages, setup

package_name = 'robot_site'

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
    description='Telerobotic ultrasound, the robot site: the robot holding the probe, its '
                'patient, the patient-side safety and the follower.',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'make_phantom = robot_site.phantom:main',
            'sim_robot = robot_site.robot_node:main',
            'teleop_follower = robot_site.follower_node:main',
        ],
    },
)

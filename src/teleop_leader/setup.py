from glob import glob

from setuptools import find_packages, setup

package_name = 'teleop_leader'

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
    zip_safe=False,
    maintainer='Haptic toolkit maintainers',
    maintainer_email='maintainers@haptic-telesono.invalid',
    description='Telerobotic ultrasound, the operator site: the leader between the wand and '
                'the link.',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'teleop_leader = teleop_leader.leader_node:main',
        ],
    },
)

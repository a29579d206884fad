from glob import glob

from setuptools import find_packages, setup

package_name = 'haptic_bringup'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/launch', glob('launch/*.launch.py')),
    ],
    install_requires=['setuptools'],
    zip_safe=False,
    maintainer='Haptic toolkit maintainers',
    maintainer_email='maintainers@haptic-telesono.invalid',
    description='Launch file, local launcher, composed loop, bag recorder and the demo.',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'haptic_loop = haptic_bringup.launcher:main',
            'composed = haptic_bringup.composed:main',
            'recorder = haptic_bringup.recorder:main',
            'demo = haptic_bringup.demo:main',
            'haptic_bag = haptic_bringup.bag_tool:main',
            'haptic_site = haptic_bringup.site:main',
        ],
    },
)

from setuptools import find_packages, setup

package_name = 'haptic_contract'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    install_requires=['setuptools'],
    zip_safe=False,
    maintainer='Haptic toolkit maintainers',
    maintainer_email='maintainers@haptic-telesono.invalid',
    description='What crosses a topic or a package boundary: value types, their fields, checks.',
    license='Apache-2.0',
)
